// The CAN side of the command line: `craneassist emulate` (the simulated crane behind the CAN
// protocol) and the machine of `craneassist replay --backend can`.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <optional>
#include <string>

#include "craneassist/can/can_backend.hpp"
#include "craneassist/can/mapping_config.hpp"
#include "craneassist/can/socketcan.hpp"
#include "craneassist/dynamics/model.hpp"
#include "emulated_nodes.hpp"

namespace craneassist::cli {

// The mapping file, or the embedded K70M mapping (config/can/k70m_can.yaml) when file is empty.
can::CanMapping load_mapping_or_default(const std::string& file);

// replay --backend can: the SocketCAN transport and the backend on it, for a mapping already
// loaded and checked against the crane (load_machine_inputs).
class CanMachine {
 public:
  CanMachine(const dynamics::CraneModel& model, const std::string& iface,
             const can::CanMapping& mapping, const std::string& candump_log,
             double feedback_timeout_s = 0.05);
  can::CanBackend& backend() { return *backend_; }
  // Prints the counters and, after a fault, its reason and how to recover.
  void report() const;

 private:
  std::unique_ptr<can::SocketCanTransport> transport_;
  std::unique_ptr<can::CanBackend> backend_;
};

struct EmulateArgs {
  std::string iface;
  std::string config_file;
  std::string mapping_file;
  std::optional<double> payload_kg;  // the load in the emulated crane's grapple
  double feedback_period_s = 0.01;
  double lag_warning_s = 0.02;  // say so when the simulation is this far behind the wall clock
  double duration_s = 0.0;      // 0: until killed
  double command_timeout_s = 0.2;
  EmulatedFaults faults;  // hidden --test-... options
};

CLI::App* add_emulate_command(CLI::App& cli, EmulateArgs& args);
int run_emulate_command(const EmulateArgs& args);

}  // namespace craneassist::cli
