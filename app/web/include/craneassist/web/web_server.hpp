// The web view of a live run (`craneassist sim --web`, docs/web.md): an HTTP and WebSocket server
// (Boost.Beast on one I/O thread) that serves the bundled page (three.js 3-D crane, gauges, live
// plots, virtual joystick), streams the loop's cycles to it and takes the page's stick state as
// a command source.
//
// The control loop meets the server in two places, neither of which waits, allocates or throws:
//   - observer(): a CycleObserver that copies the cycle's row into a hand-over slot (try_lock;
//     a busy slot skips the cycle, the page samples at its own rate anyway);
//   - make_pad_source(): a CommandSource fed by the page's virtual gamepad (the same joystick
//     mapping as a physical pad), stamped on arrival on the steady clock. The input monitor then
//     applies the rules of every source: stale input, a released deadman and a lost connection
//     stop the crane.
//
// Who may command: a WebSocket that presents the session token (printed in the page's address)
// and, unless remote_commands is set, comes from a loopback address. One page at a time holds
// the command; another takes over only after the holder's connection has closed. Everything
// else is a viewer.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/control_loop.hpp"
#include "craneassist/dynamics/mobile_base.hpp"
#include "craneassist/input/command_source.hpp"
#include "craneassist/input/joystick_mapping.hpp"

namespace craneassist::web {

struct WebOptions {
  std::string address = "127.0.0.1";  // where to listen; 0.0.0.0 for every interface
  unsigned short port = 8080;         // 0: any free port (see WebServer::port())
  double frame_rate_hz = 30.0;        // cycles streamed to each page per second
  bool commands = true;               // false: the page is a view only
  bool remote_commands = false;       // accept commands from other hosts (with the token)
  std::string token;                  // the session token; empty: a random one
  // The wheeled base the crane stands on (sim --drive; kept by reference, it must outlive the
  // server): the frames then carry the base and the crane's place on it. nullptr: a fixed base.
  const dynamics::MobileBaseModel* base = nullptr;
};

struct WebCounters {
  std::uint64_t http_requests = 0;
  std::uint64_t pages_connected = 0;  // WebSocket sessions opened so far
  std::uint64_t frames_sent = 0;      // frame messages written, all pages
  std::uint64_t frames_dropped = 0;   // not sent because a page was behind
  std::uint64_t pad_messages = 0;     // accepted stick states
  std::uint64_t pad_refused = 0;      // from a page that may not command (token, host, holder)
  std::uint64_t pad_malformed = 0;    // not a valid stick state (counts as missing)
  std::uint64_t command_holders = 0;  // pages that took the command
};

class WebServer {
 public:
  // Binds and starts the I/O thread; throws std::runtime_error naming the address when it
  // cannot listen (port in use, bad address).
  WebServer(const WebOptions& options, const config::CraneConfig& crane);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  unsigned short port() const;
  // The page's address with the token, e.g. http://127.0.0.1:8080/?token=3f9c...
  std::string url() const;

  // The loop observer that streams the cycles (valid while the server lives).
  control::CycleObserver& observer();
  // What the observer does, for rows from elsewhere (`craneassist web`: the DDS telemetry of
  // another process). Never waits: a busy hand-over slot skips the row.
  void publish(const control::LogRow& row) noexcept;

  // The page's virtual joystick as a command source, mapped by `mapping` (one per server).
  std::unique_ptr<input::CommandSource> make_pad_source(const input::JoystickMapping& mapping);

  WebCounters counters() const;
  // The summary line of a run ("  web: ...").
  std::string report() const;

  struct Impl;  // the implementation (web_server.cpp)

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace craneassist::web
