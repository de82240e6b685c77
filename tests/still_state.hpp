// The measurement of a crane standing still at its config's initial pose, valid, no pressures:
// what the controller's and its stages' tests start from.
#pragma once

#include "craneassist/config/crane_config.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::test {

inline valves::MachineState still_state(const config::CraneConfig& cfg) {
  valves::MachineState s;
  s.q = cfg.simulation.q_initial;
  s.qdot = dynamics::JointVector::Zero(cfg.model.dof());
  s.load_pressure_pa = dynamics::JointVector::Zero(cfg.model.dof());
  s.valid = true;
  return s;
}

}  // namespace craneassist::test
