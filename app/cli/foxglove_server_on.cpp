#include <spdlog/spdlog.h>

#include <cstdio>
#include <exception>

#include "craneassist/foxglove/foxglove_server.hpp"
#include "exit_codes.hpp"
#include "foxglove_server_setup.hpp"

namespace craneassist::cli {

void add_foxglove_server_option(CLI::App& command, std::string& address) {
  command
      .add_option("--foxglove", address,
                  "Serve the run live to Foxglove over its WebSocket protocol on [HOST:]PORT "
                  "(Foxglove's default port is 8765; loopback unless a host is given; "
                  "docs/foxglove.md)")
      ->check(
          [](const std::string& text) {
            foxglove::ServerOptions o;
            std::string why;
            return foxglove::parse_listen_address(text, o, why) ? std::string() : why;
          },
          "[HOST:]PORT");
}

struct FoxgloveServerHandle::Server {
  std::unique_ptr<foxglove::FoxgloveServer> server;
};

FoxgloveServerHandle::FoxgloveServerHandle() : server_(std::make_unique<Server>()) {}
FoxgloveServerHandle::~FoxgloveServerHandle() = default;

int FoxgloveServerHandle::open(const std::string& address, const config::CraneConfig& cfg,
                               bool base, bool realtime) {
  foxglove::ServerOptions options;
  std::string why;
  if (!foxglove::parse_listen_address(address, options, why)) {
    spdlog::error("--foxglove: {}", why);
    return kExitUsage;
  }
  options.base = base;
  options.sim_time = !realtime;
  try {
    server_->server = std::make_unique<foxglove::FoxgloveServer>(options, cfg.model);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  spdlog::info("foxglove: {} (Foxglove: Open connection, Foxglove WebSocket; {})",
               server_->server->url(), realtime ? "wall clock" : "simulated time");
  return kExitOk;
}

control::CycleObserver* FoxgloveServerHandle::observer() {
  return server_->server ? &server_->server->observer() : nullptr;
}

void FoxgloveServerHandle::wait_for_subscriber(double timeout_s) {
  if (!server_->server) return;
  spdlog::info("foxglove: waiting for a client to subscribe (at most {:g} s)", timeout_s);
  if (!server_->server->wait_for_subscriber(timeout_s)) {
    spdlog::warn("foxglove: no client subscribed within {:g} s: starting", timeout_s);
  }
}

void FoxgloveServerHandle::finish() {
  if (!server_->server) return;
  server_->server->stop();
  std::printf("%s\n", server_->server->report().c_str());
}

}  // namespace craneassist::cli
