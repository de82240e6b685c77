// The outputs for Foxglove, PlotJuggler and ROS 2 tools on `sim` and `replay` (docs/foxglove.md):
// --mcap FILE records the run as MCAP; --foxglove [HOST:]PORT serves it live over the Foxglove
// WebSocket protocol. One place for both commands.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/control_loop.hpp"

namespace craneassist::cli {

struct FoxgloveArgs {
  std::string mcap_file;                  // --mcap FILE
  std::string mcap_compression = "zstd";  // --mcap-compression zstd|none
  std::string foxglove;                   // --foxglove [HOST:]PORT
  double foxglove_wait_s = 0.0;           // --foxglove-wait S: hold the start for a subscriber
};

void add_foxglove_options(CLI::App& command, FoxgloveArgs& args);

class FoxgloveOutputs {
 public:
  FoxgloveOutputs();
  ~FoxgloveOutputs();
  FoxgloveOutputs(const FoxgloveOutputs&) = delete;
  FoxgloveOutputs& operator=(const FoxgloveOutputs&) = delete;

  // Opens what the options ask for (base: the crane stands on a wheeled base; realtime: the live
  // server follows the wall clock, else it offers the `time` capability). Returns kExitOk, or logs
  // why (a file that cannot be written, a port in use) and returns kExitRuntime.
  int open(const FoxgloveArgs& args, const config::CraneConfig& cfg, bool base, bool realtime);
  // Appends the loop observers (none when nothing was asked for).
  void add_observers(std::vector<control::CycleObserver*>& observers);
  // After the run: prints the report lines; kExitRuntime when the recording failed.
  int finish();

 private:
  struct Outputs;
  std::unique_ptr<Outputs> outputs_;
};

}  // namespace craneassist::cli
