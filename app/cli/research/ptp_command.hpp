// `craneassist research ptp`: an energy-optimal point-to-point move of a planar arm's tip with
// posture and (on the MHSB circuit) modes, paper 001's planner (research/planner/ptp_planner.hpp,
// docs/mhsb.md#the-planner): the optimal posture table (built once, cached), A* over the grid,
// the time trajectory with its mode schedule, written as a joint trajectory with mode columns.
#pragma once

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/planner/posture_table.hpp"
#include "craneassist/planner/ptp_planner.hpp"

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
  double continuity_tolerance = 0.0;
  std::string posture = "optimal";   // optimal | fixed-last:ANGLE (paper 001 Case 4)
  std::string out;                   // joint trajectory CSV; empty: none
  std::string path_out;              // the S2 path's nodes as CSV; empty: none
  std::string workspace_out;         // the grid's nodes with their all-N posture; empty: none
  bool simulate = false;             // run the plan on the MHSB simulator
  std::string simulate_log;          // its per-period CSV; empty: none
  std::vector<std::string> goal_at;  // "T:X,Z" goal changes (with --simulate)
};

CLI::App* add_ptp_command(CLI::App& cli, PtpArgs& args);

// "a,b,..." as exactly `count` finite numbers, or a CLI::ValidationError naming the option.
std::vector<double> parse_numbers(const std::string& option, const std::string& text,
                                  std::size_t count, const char* what);

// The planner's weights "w1,w2,w3" (energy, time, switches; none negative) and a grid spacing
// quantity (5 mm to 5 m), or a CLI::ValidationError naming the option.
planner::PtpWeights parse_weights(const std::string& option, const std::string& text);
double parse_grid_spacing(const std::string& option, const std::string& text);

// A grid spacing whose table would take hours (planner::kMaxGridCells) is a CLI::ValidationError
// naming the option and the finest spacing allowed.
void check_grid_size(const planner::PlanarArm& arm, const std::string& crane, double spacing_m,
                     const std::string& option);

// Each (option, point) must have a reachable grid node within half a diagonal, else a
// CLI::ValidationError naming the option.
void check_in_workspace(const planner::WorkspaceGrid& grid, const std::string& crane,
                        const std::vector<std::pair<std::string, Eigen::Vector2d>>& points);

// The posture table for arm (ptp and sim --input goal): from table_option's file (empty: the
// default cache) when it matches, else built (a line on stderr) and written there. The points are
// checked against the workspace first; one outside it is a CLI::ValidationError naming its
// option.
struct LoadedTable {
  planner::PostureTable table;
  bool loaded = false;  // from the file
  std::optional<std::filesystem::path> file;
};
LoadedTable posture_table_for(const config::CraneConfig& cfg, const planner::PlanarArm& arm,
                              const planner::PostureTableSettings& settings,
                              const std::string& table_option,
                              const std::vector<std::pair<std::string, Eigen::Vector2d>>& points);
int run_ptp_command(const PtpArgs& args);

}  // namespace craneassist::cli
