// The simulated crane as a crane config describes it: shared by the commands that run on the
// simulator (replay, sim).
#pragma once

#include "craneassist/config/crane_config.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

namespace craneassist::offline {

inline sim_backend::SimSettings sim_settings(const config::CraneConfig& cfg) {
  sim_backend::SimSettings s;
  s.step_s = cfg.simulation.step_s;
  s.q_initial = cfg.simulation.q_initial;
  s.pressure_noise_pa = cfg.simulation.pressure_noise_pa;
  s.pressure_resolution_pa = cfg.simulation.pressure_resolution_pa;
  s.return_pressure_pa = cfg.simulation.return_pressure_pa;
  s.valves = cfg.simulation.valves;
  s.joints = cfg.simulation.joints;
  s.swing_sensor = cfg.simulation.swing_sensor;
  s.swing_noise_rad = cfg.simulation.swing_noise_rad;
  s.swing_resolution_rad = cfg.simulation.swing_resolution_rad;
  s.grapple = cfg.simulation.grapple;
  return s;
}

}  // namespace craneassist::offline
