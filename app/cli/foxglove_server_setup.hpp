// --foxglove [HOST:]PORT: the Foxglove WebSocket server of a run. Built with the web view's
// Boost.Beast (foxglove_server_on.cpp); without it (CRANEASSIST_WEB=OFF) the option says so
// (foxglove_server_none.cpp).
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/control_loop.hpp"

namespace craneassist::cli {

void add_foxglove_server_option(CLI::App& command, std::string& address);

class FoxgloveServerHandle {
 public:
  FoxgloveServerHandle();
  ~FoxgloveServerHandle();
  FoxgloveServerHandle(const FoxgloveServerHandle&) = delete;
  FoxgloveServerHandle& operator=(const FoxgloveServerHandle&) = delete;

  // Listens on `address` ([HOST:]PORT, checked by the option); realtime: false offers the
  // `time` capability (a run faster than real time). Logs the URL; returns kExitOk, or logs why it
  // cannot listen and returns kExitRuntime.
  int open(const std::string& address, const config::CraneConfig& cfg, bool base, bool realtime);
  control::CycleObserver* observer();
  // Waits (logging it) until a client subscribes, at most timeout_s.
  void wait_for_subscriber(double timeout_s);
  // Sends what is left, closes the connections, prints the counters line.
  void finish();

 private:
  struct Server;
  std::unique_ptr<Server> server_;
};

}  // namespace craneassist::cli
