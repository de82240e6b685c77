// `--foxglove [HOST:]PORT` (sim, replay): the run live to Foxglove (and PlotJuggler's Foxglove
// bridge client) over the Foxglove WebSocket protocol (Boost.Beast, one I/O thread), with the
// channels of channels.hpp. Either subprotocol: `foxglove.sdk.v1` (what foxglove_bridge 3.x and
// the Foxglove SDK speak) or `foxglove.websocket.v1` (the npm client's); the server picks the
// first of these the client offers.
//
// The loop meets the server in observer(), which copies the cycle's row into a preallocated ring
// and returns (no lock, no allocation; a full ring drops the cycle and counts it). The I/O
// thread drains the ring every 2 ms and sends each subscribed channel's message for every cycle;
// a client that falls behind (more than max_queue_bytes waiting) loses messages, counted, and
// never slows anyone else. With `time` (a run that is not real time) every cycle also sends the
// machine time (the `time` capability). Client messages other than subscribe and unsubscribe
// (there is no command input here), and malformed ones, are counted, answered with a status
// message and dropped.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/dynamics/model.hpp"

namespace craneassist::foxglove {

struct ServerOptions {
  std::string address = "127.0.0.1";      // loopback unless a host is given
  unsigned short port = 8765;             // Foxglove's default; 0: any free port (see port())
  bool base = false;                      // the crane stands on a wheeled base: /craneassist/base
  bool sim_time = false;                  // not real time: the `time` capability
  std::size_t max_queue_bytes = 1 << 20;  // per client
  std::size_t ring_rows = 1 << 10;
};

// "8765", "0.0.0.0:8765", "[::1]:8765" into options; false (and why) when not valid.
bool parse_listen_address(const std::string& text, ServerOptions& options, std::string& why);

// A client's text message (Foxglove WebSocket protocol): what the server does with it. Only
// subscribe and unsubscribe are offered; any other op is unsupported, anything that is not a JSON
// object with a string "op" (or a subscribe/unsubscribe without its array) is malformed.
// Entries of the array that are not valid are counted in bad_items and left out.
struct ClientRequest {
  enum class Kind { kMalformed, kUnsupported, kSubscribe, kUnsubscribe };
  Kind kind = Kind::kMalformed;
  std::string op;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> subscribe;  // subscription id, channel id
  std::vector<std::uint32_t> unsubscribe;                          // subscription ids
  int bad_items = 0;
  std::string why;  // for the status reply ("" when all is well)
};
ClientRequest parse_client_request(std::string_view text);

struct ServerCounters {
  std::uint64_t clients_connected = 0;
  std::uint64_t subscriptions = 0;
  std::uint64_t messages_sent = 0;       // message data frames queued for a client
  std::uint64_t messages_dropped = 0;    // not sent: the client was behind
  std::uint64_t cycles_dropped = 0;      // the ring from the loop was full
  std::uint64_t client_malformed = 0;    // not valid JSON, or not a valid subscribe/unsubscribe
  std::uint64_t client_unsupported = 0;  // valid, but not offered (publish, parameters, ...)
  std::uint64_t refused = 0;             // HTTP without a WebSocket upgrade or subprotocol
};

class FoxgloveServer {
 public:
  // Binds and starts the I/O thread; throws std::runtime_error naming the address when it
  // cannot listen.
  FoxgloveServer(const ServerOptions& options, const dynamics::CraneModel& model);
  ~FoxgloveServer();
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  unsigned short port() const;
  std::string url() const;  // ws://HOST:PORT
  control::CycleObserver& observer();
  // Waits until a client has subscribed to a channel and its subscriptions have settled (0.2 s
  // without a new one), at most timeout_s; false when none subscribed.
  // Before the run (not on the loop's thread).
  bool wait_for_subscriber(double timeout_s) const;
  // Sends what the loop handed over, then closes every connection (at most `drain_s`).
  void stop(double drain_s = 0.5);
  ServerCounters counters() const;
  std::string report() const;  // "  foxglove: ..."

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace craneassist::foxglove
