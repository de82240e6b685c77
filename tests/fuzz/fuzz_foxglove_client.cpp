// The Foxglove WebSocket server's client messages (foxglove::parse_client_request,
// docs/foxglove.md), which arrive from any client: any bytes are malformed, unsupported, or a
// subscribe/unsubscribe whose entries are all valid 32-bit ids; never a crash or an exception.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "craneassist/foxglove/foxglove_server.hpp"
#include "fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using craneassist::foxglove::ClientRequest;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const ClientRequest r = craneassist::foxglove::parse_client_request(text);
  FUZZ_CHECK(r.bad_items >= 0, "a count");
  if (r.kind == ClientRequest::Kind::kMalformed || r.kind == ClientRequest::Kind::kUnsupported) {
    FUZZ_CHECK(!r.why.empty(), "a refusal says why");
    FUZZ_CHECK(r.subscribe.empty() && r.unsubscribe.empty(), "nothing to do when refused");
  }
  if (r.kind == ClientRequest::Kind::kSubscribe) FUZZ_CHECK(r.unsubscribe.empty(), "one op");
  if (r.kind == ClientRequest::Kind::kUnsubscribe) FUZZ_CHECK(r.subscribe.empty(), "one op");
  return 0;
}
