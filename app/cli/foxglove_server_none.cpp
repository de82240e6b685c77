#include <spdlog/spdlog.h>

#include "exit_codes.hpp"
#include "foxglove_server_setup.hpp"

namespace craneassist::cli {

void add_foxglove_server_option(CLI::App& command, std::string& address) {
  command.add_option("--foxglove", address,
                     "Not in this build (CRANEASSIST_WEB=OFF: no Boost.Beast server)");
}

struct FoxgloveServerHandle::Server {};

FoxgloveServerHandle::FoxgloveServerHandle() = default;
FoxgloveServerHandle::~FoxgloveServerHandle() = default;

int FoxgloveServerHandle::open(const std::string&, const config::CraneConfig&, bool, bool) {
  spdlog::error(
      "--foxglove: this craneassist was built without the web server "
      "(CRANEASSIST_WEB=OFF); build with it for the Foxglove WebSocket server");
  return kExitUsage;
}

control::CycleObserver* FoxgloveServerHandle::observer() {
  return nullptr;
}

void FoxgloveServerHandle::wait_for_subscriber(double) {}

void FoxgloveServerHandle::finish() {}

}  // namespace craneassist::cli
