// The machine behind `craneassist replay` and `craneassist sim`: the simulated crane or a machine
// on a CAN bus, chosen by --backend or the crane config's `backend:` and `can:` values. One
// place for the options, the choice, the start-up and the normal end, used by both commands.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "can_commands.hpp"
#include "craneassist/config/base_config.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/sim_backend/mobile_crane_backend.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::cli {

// Empty values take the config's `backend:` and `can:` values.
struct BackendArgs {
  std::string backend;                       // sim | can
  std::string can_iface;                     // --backend can: the interface
  std::string mapping_file;                  // --backend can: the mapping YAML
  std::string can_log;                       // --backend can: candump -L log of all traffic
  std::optional<double> feedback_timeout_s;  // --backend can: lost feedback after this long
};

// --backend, --can, --mapping, --can-log, --can-feedback-timeout.
void add_backend_options(CLI::App& command, BackendArgs& args);

// The resolved choice: --backend, else the config's `backend:`.
bool uses_can_backend(const BackendArgs& args, const config::CraneConfig& cfg);

// What the machine of a run needs from files, read and checked with the run's other inputs,
// before anything is opened: on the can backend the CAN mapping (--mapping, else the config's
// can.mapping, else the embedded K70M one), checked against the crane (can::check_mapping_fits).
struct MachineInputs {
  std::optional<can::CanMapping> mapping;
};
// Throws config::ConfigError naming the file, line and field (an input error: exit 2).
MachineInputs load_machine_inputs(const config::CraneConfig& cfg, const BackendArgs& args);

// Applies the backend options that override config fields (--can-feedback-timeout, through
// can.feedback_timeout's range check). Throws CLI::ValidationError naming the option.
void apply_backend_options(config::CraneConfig& cfg, const BackendArgs& args);

// Holds the machine of a run: the simulator or the CAN machine (transport and backend). Callers
// use the machine through its interface only.
class Machine {
 public:
  valves::MachineInterface& get() { return *machine_; }
  // Builds and activates the machine (a bus machine claims its J1939 address, when its mapping
  // says so, and waits up to 2 s for every joint's feedback) from the inputs
  // load_machine_inputs read. Returns kExitOk, or logs why not (with the bus report after a
  // fault, e.g. the address lost) and returns the exit code.
  // base: the simulated crane stands on this wheeled base (sim --drive; the sim backend only),
  // at the origin facing x, driven through ValveCommand::drive_*.
  int open(const config::CraneConfig& cfg, const BackendArgs& args, const MachineInputs& inputs,
           const config::BaseConfig* base = nullptr);
  // The normal end of a run: the machine deactivated (every valve to its safe state, its
  // threads ended) and the bus report printed. Returns kExitRuntime after a latched fault.
  int finish();

 private:
  std::optional<sim_backend::SimBackend> sim_;
  std::optional<sim_backend::MobileCraneBackend> mobile_;
  std::optional<CanMachine> can_;
  valves::MachineInterface* machine_ = nullptr;
};

}  // namespace craneassist::cli
