// Joint trajectory files (read, write, interpolate) and executing a plan in the simulator.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/trajectory_runner.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/input/joint_trajectory.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"
#include "craneassist/studies/planning.hpp"
#include "craneassist/valves/proportional_valves.hpp"

namespace {

using namespace craneassist;

constexpr const char* kTwoJoints =
    "# a comment\n"
    "t,q_1,q_2,qdot_1,qdot_2,qddot_1,qddot_2\n"
    "0, 0, 1, 0, 0, 0, 0\n"
    "\n"
    "1, 1, 1, 2, 0, 0, 0\r\n"
    "2, 2, 0.5, 0, 0, 0, 0\n";

std::string error_of(std::string_view text) {
  try {
    input::JointTrajectory::parse(text, "traj.csv");
  } catch (const input::FileError& e) {
    return e.what();
  }
  return "no error";
}

TEST(JointTrajectory, ParsesAndKeepsComments) {
  const auto t = input::JointTrajectory::parse(kTwoJoints, "traj.csv");
  EXPECT_EQ(t.joints(), 2);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t.t_s(1), 1.0);
  EXPECT_EQ(t.q(2)[1], 0.5);
  EXPECT_EQ(t.qdot(1)[0], 2.0);
  ASSERT_EQ(t.comments.size(), 1u);
  EXPECT_EQ(t.comments[0], "a comment");
}

TEST(JointTrajectory, ErrorsNameFileLineAndColumn) {
  EXPECT_EQ(error_of("t,q_1,qdot_1,qddot_1\n0,0,0,0\n1,x,0,0\n"),
            "traj.csv:3: field 'q_1': not a number: 'x'");
  EXPECT_EQ(error_of("t,q_1,qdot_1,qddot_1\n0,0,0,0\n0,1,0,0\n"),
            "traj.csv:3: field 't': time not strictly increasing: 0 s follows 0 s (line 2)");
  EXPECT_EQ(error_of("t,q_1,qdot_1,qddot_1\n0,0,0\n"),
            "traj.csv:2: expected 4 fields (t,q_1,qdot_1,qddot_1), got 3");
  EXPECT_EQ(error_of("t,q_1,qdot_1,qddot_1\n0,0,nan,0\n"),
            "traj.csv:2: field 'qdot_1': not a finite number: 'nan'");
  EXPECT_EQ(error_of("t,x,y\n"),
            "traj.csv:1: expected the header 't,q_1,qdot_1,qddot_1', got 't,x,y'");
  EXPECT_EQ(error_of("# nothing\n"),
            "traj.csv:1: missing header 't,q_1,qdot_1,qddot_1' (no line other than comments and "
            "blank lines)");
}

TEST(JointTrajectory, WriteThenReadIsExact) {
  auto t = input::JointTrajectory::parse(kTwoJoints, "traj.csv");
  t.comments = {"written", "twice"};
  std::ostringstream out;
  input::write_joint_trajectory(out, t);
  const auto back = input::JointTrajectory::parse(out.str(), "again.csv");
  ASSERT_EQ(back.size(), t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_EQ(back.t_s(i), t.t_s(i));
    EXPECT_EQ(back.q(i), t.q(i));
    EXPECT_EQ(back.qdot(i), t.qdot(i));
    EXPECT_EQ(back.qddot(i), t.qddot(i));
  }
  EXPECT_EQ(back.comments, t.comments);
}

// Found by fuzz_joint_trajectory: a comment line ending in "\r\r\n" kept one carriage return in
// its text, which write_joint_trajectory wrote back as "...\r\n": read again, the comment had
// lost it. Trailing carriage returns are not part of a comment.
TEST(JointTrajectory, CommentsWithStrayCarriageReturnsRoundTrip) {
  const auto t = input::JointTrajectory::parse(
      "# planned\r\r\r\n#\r\r\nt,q_1,qdot_1,qddot_1\r\n0,0,0,0\r\n", "traj.csv");
  ASSERT_EQ(t.comments, (std::vector<std::string>{"planned", ""}));
  std::ostringstream out;
  input::write_joint_trajectory(out, t);
  EXPECT_EQ(input::JointTrajectory::parse(out.str(), "again.csv").comments, t.comments);
}

TEST(JointTrajectory, SamplingReproducesAQuintic) {
  // Quintic Hermite interpolation is exact for a quintic polynomial.
  const auto p = [](double t) {
    return 0.3 - t + 0.5 * t * t + 0.2 * std::pow(t, 3) - 0.05 * std::pow(t, 5);
  };
  const auto pd = [](double t) { return -1 + t + 0.6 * t * t - 0.25 * std::pow(t, 4); };
  const auto pdd = [](double t) { return 1 + 1.2 * t - std::pow(t, 3); };
  input::JointTrajectory traj(1);
  for (double t : {0.0, 0.4, 1.0, 1.7}) {
    traj.append(t, Eigen::VectorXd::Constant(1, p(t)), Eigen::VectorXd::Constant(1, pd(t)),
                Eigen::VectorXd::Constant(1, pdd(t)));
  }
  Eigen::VectorXd q(1), qd(1);
  for (double t = 0.0; t <= 1.7; t += 0.013) {
    traj.sample(t, q, qd);
    EXPECT_NEAR(q[0], p(t), 1e-12) << t;
    EXPECT_NEAR(qd[0], pd(t), 1e-11) << t;
  }
  traj.sample(5.0, q, qd);  // held at the end, at rest
  EXPECT_NEAR(q[0], p(1.7), 1e-15);
  EXPECT_EQ(qd[0], 0.0);
}

// Found by fuzz_joint_trajectory: a NaN time passed every range check and the search for its
// segment ran past the last sample (a heap read out of bounds). It holds the first sample.
TEST(JointTrajectory, NanTimeHoldsTheFirstSample) {
  const auto traj = input::JointTrajectory::parse(
      "t,q_1,q_2,qdot_1,qdot_2,qddot_1,qddot_2\n0,0.1,0.2,0.5,0.5,0,0\n1,0.3,0.4,0,0,0,0\n",
      "traj.csv");
  Eigen::VectorXd q(2), qd(2);
  traj.sample(std::numeric_limits<double>::quiet_NaN(), q, qd);
  EXPECT_EQ(q, traj.q(0));
  EXPECT_EQ(qd, Eigen::VectorXd::Zero(2));
}

TEST(TrajectoryRunner, SimulatedCraneFollowsAPlan) {
  auto cfg = config::default_crane_config();
  const auto& m = cfg.model;
  // A 4 s horizontal quintic move planned by the DP on a small grid.
  planner::TipSamples s;
  s.dt_s = 0.05;
  const Eigen::Vector3d a(3.2, 1.5, 1.0), b(4.8, 1.5, 1.0);
  for (int k = 0; k <= 80; ++k) {
    const double x = k / 80.0, x2 = x * x, x3 = x2 * x;
    s.p_m.push_back(a + (b - a) * x3 * (10 - 15 * x + 6 * x2));
    s.v_m_s.push_back((b - a) * 30 * x2 * (1 - 2 * x + x2) / 4.0);
    s.a_m_s2.push_back((b - a) * 60 * x * (1 - 3 * x + 2 * x2) / 16.0);
  }
  planner::StageModel stages(m, s, {});
  planner::DpOptions options;
  options.grid = {80, 31, 41};
  options.refinement.passes = 1;
  const auto plan = planner::plan_dp(stages, 0.3, options);
  ASSERT_TRUE(plan.ok);
  const auto traj = studies::to_joint_trajectory(plan, "test");
  ASSERT_EQ(traj.size(), 81u);
  EXPECT_EQ(traj.comments.size(), 3u);

  sim_backend::SimBackend machine(m, {cfg.simulation.step_s, dynamics::JointVector(traj.q(0))});
  const auto summary = control::run_trajectory(cfg, traj, machine, {}, nullptr);
  EXPECT_LT(summary.start_error_m, 1e-6);
  EXPECT_LT(summary.max_tip_error_m, 0.02);
  EXPECT_LT(summary.rms_tip_error_m, 0.01);
  EXPECT_GT(summary.energy_j, 0.9 * plan.total_cost);  // the model predicts the machine
  EXPECT_LT(summary.energy_j, 1.1 * plan.total_cost);
  EXPECT_EQ(summary.invalid_state_cycles, 0);
  std::printf("tip error max %.4f rms %.4f m, energy %.0f J (plan %.0f J)\n",
              summary.max_tip_error_m, summary.rms_tip_error_m, summary.energy_j, plan.total_cost);

  // Without the preview the machine lags the plan by its valve delay: a larger error.
  sim_backend::SimBackend lagging(m, {cfg.simulation.step_s, dynamics::JointVector(traj.q(0))});
  control::TrajectoryRunOptions no_preview;
  no_preview.preview = false;
  const auto late = control::run_trajectory(cfg, traj, lagging, no_preview, nullptr);
  EXPECT_GT(late.rms_tip_error_m, summary.rms_tip_error_m);
}

}  // namespace

namespace {

// The valve activation rule (paper 000 appendix A) the trajectory follower applies: a cylinder at
// rest within activation_error keeps its section closed; beyond it, or with a reference above
// activation_speed, the section opens.
TEST(ProportionalValves, ActivationRuleKeepsRestingSectionsClosed) {
  const auto cfg = config::default_crane_config();
  EXPECT_DOUBLE_EQ(cfg.control.activation_speed_m_s, 1e-4);
  EXPECT_DOUBLE_EQ(cfg.control.activation_error_m, 1e-3);
  const valves::ProportionalValves with_rule(cfg.model, 2.0, 1e-4, 1e-3);
  const valves::ProportionalValves without_rule(cfg.model, 2.0);
  valves::ProportionalValvesInput in;
  in.velocity_ref_m_s = dynamics::JointVector::Zero(4);
  in.position_error_m = dynamics::JointVector::Zero(4);
  in.velocity_ref_m_s[1] = 5e-5;  // creeping: below activation_speed
  in.position_error_m[1] = 5e-4;  // and within activation_error
  in.velocity_ref_m_s[2] = 5e-5;  // creeping,
  in.position_error_m[2] = 2e-3;  // but too far off
  in.velocity_ref_m_s[3] = 0.05;  // moving
  valves::ValveCommand a, b;
  with_rule.update(in, a);
  without_rule.update(in, b);
  EXPECT_EQ(a.spool[0], 0.0);
  EXPECT_EQ(a.spool[1], 0.0);
  EXPECT_NE(b.spool[1], 0.0);  // without the rule the creeping section opens
  EXPECT_EQ(a.spool[2], b.spool[2]);
  EXPECT_GT(std::abs(a.spool[2]), cfg.model.valves.dead_zone);
  EXPECT_EQ(a.spool[3], b.spool[3]);
}

// A plan is for one crane: given its joints' ranges, a position outside them (a plan for another
// crane, an edited file) is refused at its line and column, as is a file for another joint count.
TEST(JointTrajectory, PositionsOutsideTheCranesRangesAreRejected) {
  input::TrajectoryLimits limits;
  limits.joints = {{"slew", -3.0, 3.0, "rad"}, {"extension", 0.0, 3.7, "m"}};
  const auto error = [&](std::string_view text) {
    try {
      input::JointTrajectory::parse(text, "traj.csv", limits);
    } catch (const input::FileError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string header = "# plan\nt,q_1,q_2,qdot_1,qdot_2,qddot_1,qddot_2\n";
  EXPECT_EQ(
      error(header + "0,0,0,0,0,0,0\n1,0,3.75,0,0,0,0\n"),
      "traj.csv:4: field 'q_2': 3.75 m is outside the range of joint 'extension', [0, 3.7] m");
  EXPECT_EQ(error(header + "0,-3.5,0,0,0,0,0\n"),
            "traj.csv:3: field 'q_1': -3.5 rad is outside the range of joint 'slew', [-3, 3] rad");
  EXPECT_EQ(error(header + "0,-3,0,0,0,0,0\n1,3,3.7,0,0,0,0\n"), "no error");  // the ends
  EXPECT_EQ(error("t,q_1,qdot_1,qddot_1\n0,0,0,0\n"),
            "traj.csv:1: the header names 1 joint (q_1), the crane has 2");
  // Without limits (no crane) only the format is checked.
  EXPECT_NO_THROW(input::JointTrajectory::parse(header + "0,9,9,0,0,0,0\n", "traj.csv"));
}

// sample() holds the first sample before the start and the last after the end for any time the
// caller may compute: NaN (which compares false with every sample and sent the search past the
// last one, a read beyond the buffer), infinities, negative and huge times.
TEST(JointTrajectory, SamplingHoldsTheEndsForEveryTime) {
  const auto traj = input::JointTrajectory::parse(kTwoJoints, "traj.csv");
  Eigen::VectorXd q(2), qd(2);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (const double t : {std::numeric_limits<double>::quiet_NaN(), -kInf, -1.0, -1e300}) {
    traj.sample(t, q, qd);
    EXPECT_EQ(q, traj.q(0)) << t;
    EXPECT_EQ(qd, Eigen::VectorXd::Zero(2)) << t;
  }
  for (const double t : {2.5, 1e300, kInf}) {
    traj.sample(t, q, qd);
    EXPECT_EQ(q, traj.q(2)) << t;
    EXPECT_EQ(qd, Eigen::VectorXd::Zero(2)) << t;
  }
}

}  // namespace
