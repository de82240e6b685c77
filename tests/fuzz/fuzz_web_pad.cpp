// The web page's stick state messages (web::parse_pad_message, docs/web.md), which arrive over a
// WebSocket from any page: any bytes are refused, or give up to six axes in -1..1.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_check.hpp"
#include "pad_message.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  craneassist::web::PadMessage m;
  if (craneassist::web::parse_pad_message(text, m)) {
    for (const double a : m.axes) {
      FUZZ_CHECK(std::isfinite(a) && std::abs(a) <= 1.0, "an axis in -1..1");
    }
  }
  return 0;
}
