// A point-to-point plan of the MHSB arm (planner/ptp_planner.hpp) executed on the MHSB simulator
// (mhsb/mhsb_simulator.hpp) under the paper's cascade controller, for `craneassist research ptp
// --simulate` and docs/mhsb.md: the planned joint trajectory and its S4 mode schedule are the
// controller's reference; the goal may change while the arm moves (paper 001 section 4.2), each
// change replanned from the reference's posture at that moment, the new trajectory taking over
// from there.
#pragma once

#include <Eigen/Core>
#include <ostream>
#include <vector>

#include "craneassist/mhsb/mhsb_simulator.hpp"
#include "craneassist/planner/ptp_planner.hpp"

namespace craneassist::studies {

// A goal (X, Z in the arm's plane) that replaces the current one at t_s.
struct PtpGoalChange {
  double t_s = 0.0;
  Eigen::Vector2d xz = Eigen::Vector2d::Zero();
};

// One plan of the run: the initial one, then one per goal change.
struct PtpSegment {
  double start_s = 0.0;  // run time its trajectory starts
  Eigen::Vector2d from = Eigen::Vector2d::Zero(), to = Eigen::Vector2d::Zero();
  planner::PtpPlan plan;
};

struct PtpSimulation {
  std::vector<PtpSegment> segments;
  double duration_s = 0.0;  // simulated
  // The planned energy of what was executed: each segment's S4 energy up to the next segment's
  // start (all of the last one), J.
  double planned_energy_j = 0.0;
  mhsb::MhsbRunSummary measured;
  double final_error_rad = 0.0;  // the largest joint error at the end
};

// Plans from `from` to `to`, then runs the simulator from the plan's first posture until the last
// segment's trajectory ends (plus settle_s). Throws std::invalid_argument (a point outside the
// workspace), std::runtime_error (no path to a goal) and what MhsbSimulator throws.
PtpSimulation simulate_ptp(planner::PtpPlanner& planner, const Eigen::Vector2d& from,
                           const Eigen::Vector2d& to, const planner::PtpWeights& weights,
                           const std::vector<PtpGoalChange>& changes, double settle_s,
                           std::ostream* csv);

}  // namespace craneassist::studies
