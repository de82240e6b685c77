// Paper 000's energy experiment in simulation: every redundancy resolution (the four online
// ones driven along the path, and the DP planner with each of its four costs) on every test
// path, from both start configurations, executed in the simulator with a load-sensing and with
// a constant-pressure pump; the measured pump energy of each run.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/studies/planning.hpp"

namespace craneassist::studies {

struct EnergyExperimentOptions {
  std::vector<std::filesystem::path> paths;  // tip path files
  planner::DpOptions dp;                     // grid, refinement, threads
  double dt_s = 0.05;
  double cp_supply_pressure_pa = 20e6;  // the constant-pressure system (paper 000 section 6)
  // Progress messages (one per plan and per simulated path), from the calling thread.
  std::function<void(const std::string&)> progress;
};

struct EnergyRun {
  std::string path;    // file stem, e.g. "horizontal"
  std::string start;   // "shortest" or "middle"
  std::string method;  // "pinv-joint", ..., "dp-ls", "dp-cp", "dp-actuator-energy", "dp-extension"
  std::string system;  // "ls" or "cp"
  double energy_j = 0.0;        // measured in the simulator
  double model_energy_j = 0.0;  // the planner's model of the same system for the same plan
  double max_tip_error_m = 0.0, rms_tip_error_m = 0.0;
  double peak_power_w = 0.0;
  int penalised_stages = 0;  // stages of the plan that violate a cylinder limit
  long pump_saturated_cycles = 0;
  double plan_time_s = 0.0;  // planning wall time (the DP's backward phase is shared by starts)
};

// Throws on unreadable paths or an unreachable start.
std::vector<EnergyRun> run_energy_experiment(const config::CraneConfig& config,
                                             const EnergyExperimentOptions& options);

void write_energy_csv(std::ostream& out, const std::vector<EnergyRun>& runs);

}  // namespace craneassist::studies
