// `craneassist research plan`: plan the redundancy along a prescribed tip path and write the
// trajectory. `craneassist research energy`: paper 000's energy experiment in simulation
// (docs/energy.md).
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "craneassist/planner/dp_planner.hpp"

namespace craneassist::cli {

struct PlanArgs {
  std::string path_file;
  std::string config_file;  // empty: the embedded reference crane
  std::string cost = "ls";
  std::string method = "dp";
  std::string out_file = "craneassist-plan.csv";
  std::string start = "shortest";
  std::string grid = "356x101x151";
  int refine = 3;
  int threads = 0;
  double dt_s = 0.05;
  std::optional<double> payload_kg;
  bool quiet = false;
};

CLI::App* add_plan_command(CLI::App& cli, PlanArgs& args);
int run_plan_command(const PlanArgs& args);

// "NxMxK" (DP grid sizes, each 2..5000); false when malformed.
bool parse_dp_grid(const std::string& text, planner::DpGrid& grid);

}  // namespace craneassist::cli
