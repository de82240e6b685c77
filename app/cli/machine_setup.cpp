#include "machine_setup.hpp"

#include <spdlog/spdlog.h>

#include "crane_options.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"

namespace craneassist::cli {

void add_backend_options(CLI::App& command, BackendArgs& args) {
  command
      .add_option("--backend", args.backend,
                  "Machine backend: sim (the simulated crane) or can (a machine on a CAN bus, "
                  "docs/can.md; implies real-time pacing). Default: the config's `backend:` (sim)")
      ->check(CLI::IsMember(names_of(config::kBackendKinds)));
  command.add_option("--can", args.can_iface,
                     "--backend can: the CAN interface (can0, vcan0; default: can.interface)");
  command
      .add_option("--mapping", args.mapping_file,
                  "--backend can: CAN mapping YAML (default: can.mapping, else the embedded "
                  "config/can/k70m_can.yaml)")
      ->check(CLI::ExistingFile);
  command.add_option("--can-log", args.can_log,
                     "--backend can: write all CAN traffic as a candump -L log");
  command
      .add_option("--can-feedback-timeout", args.feedback_timeout_s,
                  "--backend can: fault when a joint's position is older than this, s, 0.001 to 1 "
                  "(default: can.feedback_timeout, 0.05)")
      ->check(FiniteNumber());  // the range is can.feedback_timeout's (apply_backend_options)
}

bool uses_can_backend(const BackendArgs& args, const config::CraneConfig& cfg) {
  const auto kind =
      args.backend.empty() ? cfg.backend.kind : config::parse_backend_kind(args.backend).value();
  return kind == config::BackendKind::kCan;
}

void apply_backend_options(config::CraneConfig& cfg, const BackendArgs& args) {
  if (args.feedback_timeout_s) {
    apply_override("--can-feedback-timeout", [&] {
      config::set_can_feedback_timeout(cfg.backend, *args.feedback_timeout_s);
    });
  }
}

MachineInputs load_machine_inputs(const config::CraneConfig& cfg, const BackendArgs& args) {
  MachineInputs inputs;
  if (uses_can_backend(args, cfg)) {
    inputs.mapping = load_mapping_or_default(args.mapping_file.empty() ? cfg.backend.can.mapping
                                                                       : args.mapping_file);
    can::check_mapping_fits(*inputs.mapping, cfg.model);
  }
  return inputs;
}

int Machine::open(const config::CraneConfig& cfg, const BackendArgs& args,
                  const MachineInputs& inputs, const config::BaseConfig* base) {
  if (base != nullptr) {
    if (uses_can_backend(args, cfg)) {
      spdlog::error("--drive: the wheeled base is simulated; it runs on the sim backend only");
      return kExitUsage;
    }
    mobile_.emplace(cfg.model, offline::sim_settings(cfg), base->model, dynamics::BasePose{},
                    base->shared_with_crane);
    machine_ = &*mobile_;
    return machine_->activate(0.0, nullptr) ? kExitOk : kExitRuntime;
  }
  if (!uses_can_backend(args, cfg)) {
    sim_.emplace(cfg.model, offline::sim_settings(cfg));
    machine_ = &*sim_;
    return machine_->activate(0.0, nullptr) ? kExitOk : kExitRuntime;
  }
  const std::string iface = args.can_iface.empty() ? cfg.backend.can.interface : args.can_iface;
  if (iface.empty()) {
    spdlog::error("the can backend needs an interface: --can IFACE or can.interface in {}",
                  cfg.source_name);
    return kExitUsage;
  }
  if (!inputs.mapping) {
    spdlog::error("the can backend's mapping was not loaded (load_machine_inputs)");
    return kExitRuntime;
  }
  can_.emplace(cfg.model, iface, *inputs.mapping, args.can_log,
               cfg.backend.can.feedback_timeout_s);  // --can-feedback-timeout applied to cfg
  machine_ = &can_->backend();
  if (std::string why; !machine_->activate(2.0, &why)) {
    if (machine_->faulted()) {  // e.g. the J1939 address belongs to another node
      spdlog::error("the machine was not activated on {}: {}", iface, why);
      can_->report();
    } else {
      spdlog::error("{} on {} (is the machine or `craneassist emulate --can {}` running?)", why,
                    iface, iface);
    }
    return kExitRuntime;
  }
  return kExitOk;
}

int Machine::finish() {
  if (machine_ == nullptr) return kExitOk;
  machine_->deactivate();
  if (can_) can_->report();
  return machine_->faulted() ? kExitRuntime : kExitOk;
}

}  // namespace craneassist::cli
