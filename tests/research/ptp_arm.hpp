// The paper 001 arm and posture-table regions the point-to-point planner's and the posture
// table's tests share (small regions of the workspace, to stay fast).
#pragma once

#include "craneassist/config/crane_config.hpp"
#include "craneassist/planner/posture_table.hpp"
#include "craneassist/planner/ptp_planner.hpp"

namespace craneassist::test {

inline planner::PtpWeights W(double energy, double time, double switches) {
  planner::PtpWeights w;
  w.energy = energy;
  w.time = time;
  w.switches = switches;
  return w;
}

inline const config::CraneConfig& arm_config() {
  static const config::CraneConfig cfg = config::mhsb_3link_config();
  return cfg;
}

// A region of the paper's arm: 5 cm grid, the first patterns only, or all of them on a 10 cm grid.
inline planner::PostureTableSettings region_settings(double spacing, int patterns) {
  planner::PostureTableSettings s;
  s.spacing_m = spacing;
  s.region = Eigen::Vector4d(0.3, -0.2, 0.8, 0.3);
  s.max_patterns = patterns;
  return s;
}

inline const planner::PlanarArm& arm() {
  static const planner::PlanarArm a(arm_config().model, arm_config().simulation.q_initial);
  return a;
}

inline const planner::PostureTable& small_table() {
  static const planner::PostureTable t =
      planner::PostureTable::build(arm(), region_settings(0.1, 0));
  return t;
}

}  // namespace craneassist::test
