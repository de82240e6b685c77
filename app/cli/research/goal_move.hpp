// The goal move of `sim --input goal`: the point-to-point planner (research/planner) behind the
// product's input::GoalPlanning, built before anything moves. The only research the product's
// `sim` reaches, and only through this.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/input/goal_planning.hpp"

namespace craneassist::cli {

struct GoalMoveOptions {
  std::string goal;                  // --goal "X,Z"
  std::vector<std::string> goal_at;  // --goal-at "T:X,Z"
  std::string weights = "0.5,0,2";   // --goal-weights
  std::string grid;                  // --goal-grid (quantity; empty: the default spacing)
  std::string table;                 // --goal-table (empty: the default cache)
  double speed_m_s = 0.5;            // --goal-speed
};

// The planner for cfg's arm with its posture table (loaded, or built and cached) and the goals.
// Throws CLI::ValidationError naming the option for a malformed goal, weight or grid, a goal
// outside the workspace or an arm the planner cannot take.
std::unique_ptr<input::GoalPlanning> make_goal_move(const config::CraneConfig& cfg,
                                                    const GoalMoveOptions& options);

}  // namespace craneassist::cli
