// `craneassist calibrate`: sweep each valve section on the simulator or on a machine (--backend
// can) and write the fitted velocity-vs-command tables (docs/valves.md).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "machine_setup.hpp"

namespace craneassist::cli {

struct CalibrateArgs {
  std::string config_file;  // empty: the embedded reference crane
  std::string section = "all";
  std::string out_file = "craneassist-valve-tables.yaml";
  std::string log_file = "craneassist-sweep.csv";
  std::vector<double> levels;  // empty: offline::CalibrationOptions' levels
  BackendArgs machine;
  bool quiet = false;
};

CLI::App* add_calibrate_command(CLI::App& cli, CalibrateArgs& args);
int run_calibrate_command(const CalibrateArgs& args);

}  // namespace craneassist::cli
