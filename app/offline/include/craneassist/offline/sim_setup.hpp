// The simulated crane as a crane config describes it: shared by the commands that run on the
// simulator (replay, sim).
#pragma once

#include "craneassist/config/crane_config.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

namespace craneassist::offline {

inline sim_backend::SimSettings sim_settings(const config::CraneConfig& cfg) {
  return sim_backend::SimSettings{cfg.simulation.step_s, cfg.simulation.q_initial};
}

}  // namespace craneassist::offline
