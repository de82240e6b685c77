// The point-to-point planner's plans run on the MHSB simulator (offline/ptp_simulation.hpp,
// docs/mhsb.md): the energy the planner expects against what the simulator meters, and the moving
// goal of paper 001 section 4.2. The posture table covers the region of the moves, all 23 patterns
// on the paper's 5 cm grid (a few seconds to build, once).
#include <gtest/gtest.h>

#include <cmath>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/studies/ptp_simulation.hpp"

namespace {

using namespace craneassist;

struct Fixture {
  config::CraneConfig cfg = config::mhsb_3link_config();
  planner::PlanarArm arm{cfg.model, cfg.simulation.q_initial};
  planner::PostureTable table;
  std::optional<planner::PtpPlanner> planner;
  Fixture() {
    planner::PostureTableSettings s;
    s.spacing_m = 0.05;
    s.region = Eigen::Vector4d(0.45, -0.1, 0.85, 0.65);
    table = planner::PostureTable::build(arm, s);
    planner.emplace(arm, table, planner::PtpSettings{});
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

planner::PtpWeights weights(double w1, double w2, double w3) {
  planner::PtpWeights w;
  w.energy = w1;
  w.time = w2;
  w.switches = w3;
  return w;
}

// The requirement: the planner's energy within 10 % of the simulator's. Paper 001's
// Case 1 points, energy-optimal and shortest-time weights.
TEST(PtpSimulation, PlannedEnergyIsWithinTenPercentOfTheSimulators) {
  for (const auto& w : {weights(0.5, 0, 2), weights(0, 15, 2)}) {
    const auto run =
        studies::simulate_ptp(*fixture().planner, {0.55, -0.05}, {0.55, 0.6}, w, {}, 0.0, nullptr);
    ASSERT_EQ(run.segments.size(), 1u);
    const double planned = run.planned_energy_j, measured = run.measured.energy_j;
    EXPECT_GT(planned, 100.0);
    EXPECT_NEAR(measured, planned, 0.10 * planned) << "w2 " << w.time;
    // The arm follows the plan: within a few degrees, and at the goal at the end.
    EXPECT_LT(run.measured.max_abs_error_any, 5.0 * M_PI / 180.0);
    EXPECT_LT(run.final_error_rad, 1.0 * M_PI / 180.0);
    EXPECT_EQ(run.measured.invalid_references, 0);
    EXPECT_EQ(run.measured.dynamics_failures, 0);
    // A plan that needs a boost gets one: the servo-pumps did work.
    bool boosted = false;
    for (const auto& s : run.segments.front().plan.samples) {
      for (int k = 0; k < 3; ++k) boosted = boosted || mhsb::is_boost(s.mode[k]);
    }
    if (boosted) {
      EXPECT_GT(run.measured.servo_pump_energy_j, 1.0);
    }
  }
}

// Paper 001 section 4.2: the goal changes at 3 s and 6 s; each change is replanned from the
// reference's posture, the trajectory stays continuous, the arm tracks it.
TEST(PtpSimulation, MovingGoalIsReplannedAndTracked) {
  const auto run =
      studies::simulate_ptp(*fixture().planner, {0.7, 0.5}, {0.6, 0.2}, weights(0.5, 0, 2),
                            {{3.0, {0.8, 0.2}}, {6.0, {0.6, 0.5}}}, 0.0, nullptr);
  ASSERT_EQ(run.segments.size(), 3u);
  EXPECT_DOUBLE_EQ(run.segments[1].start_s, 3.0);
  EXPECT_DOUBLE_EQ(run.segments[2].start_s, 6.0);
  for (std::size_t i = 1; i < run.segments.size(); ++i) {
    const auto& next = run.segments[i];
    EXPECT_TRUE(next.plan.path.found);
    EXPECT_GT(next.plan.samples.size(), 1u);
    // Replanned from where the reference was: from the previous goal only when the move before
    // had ended by the change (the first move takes about 3 s).
    const auto& before = run.segments[i - 1];
    const double gap_m = (next.from - before.to).norm();
    if (before.start_s + before.plan.time_s < next.start_s) {
      EXPECT_LT(gap_m, 1e-3) << "segment " << i;
    } else {
      EXPECT_GT(gap_m, 0.01) << "segment " << i;
    }
  }
  EXPECT_LT(run.measured.max_abs_error_any, 5.0 * M_PI / 180.0);  // the paper: 2.43 deg
  EXPECT_LT(run.final_error_rad, 1.5 * M_PI / 180.0);
  EXPECT_NEAR(run.measured.energy_j, run.planned_energy_j, 0.10 * run.planned_energy_j);
}

// A goal changed halfway through a move: the new plan starts from the reference's posture then,
// between the start and the old goal, and the reference stays continuous.
TEST(PtpSimulation, AGoalChangedWhileMovingIsPlannedFromTheReference) {
  const auto run = studies::simulate_ptp(*fixture().planner, {0.7, 0.5}, {0.6, 0.2},
                                         weights(0.5, 0, 2), {{1.5, {0.8, 0.2}}}, 0.0, nullptr);
  ASSERT_EQ(run.segments.size(), 2u);
  ASSERT_GT(run.segments[0].plan.time_s, 2.0);
  const Eigen::Vector2d from = run.segments[1].from;
  EXPECT_GT((from - run.segments[0].to).norm(), 0.01);
  EXPECT_GT((from - Eigen::Vector2d(0.7, 0.5)).norm(), 0.01);
  EXPECT_TRUE(run.segments[1].plan.path.found);
  // Not asserted: the tracking. This replan ends lowering J1 slowly in N with its cylinder's
  // holding pressure above P0 (a negative load, N by the mode rule), and the simulated arm sinks
  // 6.6 degrees by the end (docs/mhsb.md#the-other-cases).
}

}  // namespace
