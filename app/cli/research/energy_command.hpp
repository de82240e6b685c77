// `craneassist research energy`: paper 000's energy experiment in simulation (docs/energy.md):
// every resolution on every path, from both start configurations, with a load-sensing and a
// constant-pressure pump.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace craneassist::cli {

struct EnergyArgs {
  std::vector<std::string> path_files = {"examples/paths/horizontal.csv",
                                         "examples/paths/vertical.csv",
                                         "examples/paths/half_cycle.csv"};
  std::string config_file;
  std::string out_file = "energy-results.csv";
  std::string grid = "356x101x151";
  int refine = 3;
  int threads = 0;
  bool quiet = false;
};

CLI::App* add_energy_command(CLI::App& cli, EnergyArgs& args);
int run_energy_command(const EnergyArgs& args);

}  // namespace craneassist::cli
