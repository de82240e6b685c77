// `craneassist research experiment-2r`: the 2R experiment of the power-limited scaling paper (paper
// 004, section 4) on the simulated two-link arm (offline/sine_path_experiment.hpp).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "craneassist/dynamics/model.hpp"

namespace craneassist::cli {

struct ExperimentArgs {
  std::string config_file;  // empty: the embedded planar 2R arm
  std::string power_bound = dynamics::to_string(dynamics::PowerBound::kLoadSensing);
  double speed = 2.0;
  double duration_s = 8.0;
  double jerk_max = 1000.0;
  std::string log_file = "craneassist-2r.csv";
  bool no_log = false;
  bool pump_limiter = false;
};

CLI::App* add_experiment_command(CLI::App& cli, ExperimentArgs& args);
int run_experiment_command(const ExperimentArgs& args);

}  // namespace craneassist::cli
