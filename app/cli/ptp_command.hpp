// `craneassist ptp`: an energy-optimal point-to-point move of a planar arm's tip with posture and
// (on the MHSB circuit) modes, paper 001's planner (dynamics/planner/ptp_planner.hpp,
// docs/mhsb.md#the-planner): the optimal posture table (built once, cached), A* over the grid,
// the time trajectory with its mode schedule, written as a joint trajectory with mode columns.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

namespace craneassist::cli {

struct PtpArgs {
  std::string config_file;  // empty: the embedded reference crane (K70M)
  std::string from, to;     // "X,Z" in m
  std::string weights = "0.5,0,2";
  std::string velocity_limit;  // quantity; empty: the config's
  std::string grid;            // quantity; empty: the default spacing
  std::string energy_model;    // series | paper; empty: series
  std::string table;           // posture table file; empty: the default cache
  std::optional<double> heuristic_scale;
  int threads = 2;
  std::string posture = "optimal";   // optimal | fixed-last:ANGLE (paper 001 Case 4)
  std::string out;                   // joint trajectory CSV; empty: none
  std::string path_out;              // the S2 path's nodes as CSV; empty: none
  std::string workspace_out;         // the grid's nodes with their all-N posture; empty: none
  bool simulate = false;             // run the plan on the MHSB simulator
  std::string simulate_log;          // its per-period CSV; empty: none
  std::vector<std::string> goal_at;  // "T:X,Z" goal changes (with --simulate)
};

CLI::App* add_ptp_command(CLI::App& cli, PtpArgs& args);
int run_ptp_command(const PtpArgs& args);

}  // namespace craneassist::cli
