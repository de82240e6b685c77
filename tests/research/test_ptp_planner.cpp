// The point-to-point planner of paper 001 (research/planner/ptp_planner.hpp, docs/mhsb.md): the
// analytic gravity load against the ODE model, the posture table against brute force, A* against
// Dijkstra, the mode rule along found paths, the time trajectory, the table file and the joint
// trajectory's mode columns. Tables are built on small regions of the workspace to stay fast.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "craneassist/dynamics/static_gravity.hpp"
#include "craneassist/input/joint_trajectory.hpp"
#include "craneassist/planner/ptp_planner.hpp"
#include "ptp_arm.hpp"

namespace {

using namespace craneassist;
using namespace craneassist::test;
using planner::ArmVector;

TEST(StaticGravity, MatchesTheOdeModel) {
  for (const auto& cfg : {config::default_crane_config(), config::mhsb_3link_config()}) {
    dynamics::RigidBodyTerms terms(cfg.model);
    dynamics::KinematicsData data;
    std::mt19937 rng(7);
    for (int trial = 0; trial < 20; ++trial) {
      dynamics::JointVector q(cfg.model.dof());
      for (int i = 0; i < cfg.model.dof(); ++i) {
        const auto& j = cfg.model.joints[static_cast<std::size_t>(i)];
        q[i] = std::uniform_real_distribution<double>(j.q_min, j.q_max)(rng);
      }
      dynamics::JointVector g_ode, g;
      terms.gravity(q, g_ode);
      dynamics::static_gravity_effort(cfg.model, data, q, g);
      for (int i = 0; i < cfg.model.dof(); ++i) {
        EXPECT_NEAR(g[i], g_ode[i], 1e-6 * (1.0 + g_ode.cwiseAbs().maxCoeff())) << cfg.model.name;
      }
    }
  }
}

TEST(PlanarArm, TheK70MMovesLiftTiltAndExtensionInItsVerticalPlane) {
  const auto cfg = config::default_crane_config();
  const planner::PlanarArm k70(cfg.model, cfg.simulation.q_initial);
  ASSERT_EQ(k70.moving(), 3);
  EXPECT_EQ(k70.joint(0), 1);
  dynamics::KinematicsData data;
  const ArmVector a = k70.moving_part(cfg.simulation.q_initial);
  const Eigen::Vector3d tip = dynamics::tip_position(cfg.model, data, cfg.simulation.q_initial);
  EXPECT_LT((k70.from_plane(k70.tip(a, data)) - tip).norm(), 1e-9);
  EXPECT_GT(k70.tip(a, data).x(), 0.0);
  // The paper's arm: (X, Z) are the crane's (x, y).
  EXPECT_EQ(arm().moving(), 3);
  EXPECT_NEAR(arm().plane()(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(arm().plane()(1, 1), 1.0, 1e-12);
}

TEST(PtpPlanner, AStarCostEqualsDijkstras) {
  planner::PtpPlanner ptp(arm(), small_table(), {});
  const int nodes = small_table().grid().nodes();
  ASSERT_GT(nodes, 15);
  int compared = 0;
  for (const planner::PtpWeights& w : {W(0.5, 0, 2), W(0, 15, 2), W(1, 1, 0)}) {
    for (int s = 0; s < nodes; s += 4) {
      for (int g = 1; g < nodes; g += 5) {
        const auto a = ptp.search(s, g, w, planner::PtpSearch::kAStar);
        const auto d = ptp.search(s, g, w, planner::PtpSearch::kDijkstra);
        ASSERT_EQ(a.found, d.found);
        if (!a.found) continue;
        EXPECT_NEAR(a.cost, d.cost, 1e-9 * (1.0 + d.cost));
        EXPECT_LE(a.expanded, d.expanded);
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 30);
}

TEST(PtpPlanner, TransitionsObeyTheModeRule) {
  const auto& model = arm().model();
  planner::PtpPlanner ptp(arm(), small_table(), {});
  dynamics::KinematicsData data;
  int boosted = 0, checked = 0;
  for (const planner::PtpWeights& w : {W(0.5, 0, 2), W(0, 15, 2)}) {
    const auto plan = ptp.plan({0.5, -0.1}, {0.7, 0.3}, w);
    ASSERT_TRUE(plan.path.found);
    const auto& steps = plan.path.steps;
    for (std::size_t i = 1; i < steps.size(); ++i) {
      planner::PlanarArm::Statics a, b;
      arm().statics(steps[i - 1].q, data, a);
      arm().statics(steps[i].q, data, b);
      const double t = steps[i].t_s - steps[i - 1].t_s;
      ASSERT_GT(t, 0.0);
      const auto& pattern = small_table().patterns()[static_cast<std::size_t>(steps[i].pattern)];
      for (int k = 0; k < 3; ++k) {
        const double v = (b.length_m[k] - a.length_m[k]) / t;
        EXPECT_LE(std::abs(v), ptp.velocity_limit_m_s(k) * (1 + 1e-9));
        const auto mode = pattern.mode[static_cast<std::size_t>(k)];
        if (mhsb::is_boost(mode)) {
          EXPECT_LE(std::abs(v) * dynamics::flow_area_m2(model.cylinders[k], v),
                    mhsb::mode_flow_cap_m3_s(*model.mhsb, mode) * (1 + 1e-9));
        }
        const bool need = mhsb::needs_boost(model, k, a.force_n[k], v) ||
                          mhsb::needs_boost(model, k, b.force_n[k], v);
        if (v != 0.0) {
          EXPECT_EQ(need, mhsb::is_boost(mode));
          EXPECT_TRUE(mhsb::mode_allowed(model, k, mode, a.force_n[k], v) ||
                      mhsb::mode_allowed(model, k, mode, b.force_n[k], v));
        }
        // N for a negative load at both ends.
        if (!mhsb::positive_load(a.force_n[k], v) && !mhsb::positive_load(b.force_n[k], v) &&
            v != 0.0) {
          EXPECT_EQ(mode, mhsb::MhsbMode::kNormal);
        }
        boosted += mhsb::is_boost(mode) ? 1 : 0;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 20);
  EXPECT_GT(boosted, 0);  // the lift to (0.7, 0.3) needs a boost somewhere
}

TEST(PtpPlanner, TheTrajectoryRestsAtTheEndsAndPassesThroughTheNodes) {
  planner::PtpPlanner ptp(arm(), small_table(), {});
  const auto plan = ptp.plan({0.5, -0.1}, {0.7, 0.3}, W(0.5, 0, 2));
  ASSERT_TRUE(plan.path.found);
  ASSERT_GT(plan.samples.size(), 10u);
  const auto& first = plan.samples.front();
  const auto& last = plan.samples.back();
  EXPECT_EQ(first.t_s, 0.0);
  EXPECT_NEAR(last.t_s, plan.node_times_s.back(), 1e-9);
  EXPECT_LT(first.qdot.norm() + first.qddot.norm() + last.qdot.norm() + last.qddot.norm(), 1e-9);
  EXPECT_LT((first.q - plan.path.steps.front().q).norm(), 1e-12);
  EXPECT_LT((last.q - plan.path.steps.back().q).norm(), 1e-9);
  // Near each node time the trajectory is at the node's posture (within what it moves in the
  // time between), and the rates are the positions' derivatives.
  double peak_rate = 0.0;
  for (const auto& s : plan.samples) peak_rate = std::max(peak_rate, s.qdot.cwiseAbs().maxCoeff());
  ASSERT_EQ(plan.node_times_s.size(), plan.path.steps.size());
  for (std::size_t i = 0; i < plan.path.steps.size(); ++i) {
    const double t = plan.node_times_s[i];
    EXPECT_GE(t, plan.path.steps[i].t_s - 1e-9);  // S3 only ever lengthens a segment
    const auto it = std::min_element(
        plan.samples.begin(), plan.samples.end(),
        [&](const auto& l, const auto& r) { return std::abs(l.t_s - t) < std::abs(r.t_s - t); });
    EXPECT_LE((it->q - plan.path.steps[i].q).cwiseAbs().maxCoeff(),
              peak_rate * std::abs(it->t_s - t) + 1e-9);
  }
  EXPECT_LE(plan.peak_speed_ratio, 1.5 * 1.05);  // checked on 17 points per segment
  for (std::size_t i = 1; i < plan.samples.size(); ++i) {
    const auto& a = plan.samples[i - 1];
    const auto& b = plan.samples[i];
    const double dt = b.t_s - a.t_s;
    const ArmVector predicted = a.q + 0.5 * (a.qdot + b.qdot) * dt;
    EXPECT_LT((predicted - b.q).cwiseAbs().maxCoeff(), 1e-3 * dt + 2 * peak_rate * dt * dt);
  }
  EXPECT_GT(plan.energy_j, 0.0);
  EXPECT_NEAR(plan.energy_j, plan.path.energy_j, 0.3 * plan.path.energy_j);
}

// A live loop replans from where the arm is: the trajectory starts at that posture, at rest, and
// then follows the table's nodes.
TEST(PtpPlanner, ReplansFromTheArmsPosture) {
  planner::PtpPlanner ptp(arm(), small_table(), {});
  const int start = ptp.node_near({0.5, -0.1});
  ASSERT_GE(start, 0);
  // Another posture on the start node: the table's for another pattern.
  const ArmVector here = small_table().posture(start, 7);
  const auto plan = ptp.plan({0.5, -0.1}, {0.7, 0.3}, W(0.5, 0, 2), here);
  ASSERT_TRUE(plan.path.found);
  EXPECT_LT((plan.samples.front().q - here).norm(), 1e-12);
  EXPECT_LT(plan.samples.front().qdot.norm(), 1e-12);
  EXPECT_LT((plan.samples.back().q - plan.path.steps.back().q).norm(), 1e-9);
  EXPECT_LE(plan.peak_speed_ratio, 1.5 * 1.05);
}

TEST(PtpPlanner, APointOutsideTheWorkspaceIsRefused) {
  planner::PtpPlanner ptp(arm(), small_table(), {});
  EXPECT_THROW(ptp.plan({2.0, 0.0}, {0.5, 0.0}, W(0.5, 0, 2)), std::invalid_argument);
  EXPECT_THROW(ptp.plan({0.5, 0.0}, {0.0, 3.0}, W(0.5, 0, 2)), std::invalid_argument);
}

TEST(PtpPlanner, PlansTheK70MOnALoadSensingPump) {
  const auto cfg = config::default_crane_config();
  const planner::PlanarArm k70(cfg.model, cfg.simulation.q_initial);
  planner::PostureTableSettings s;
  s.spacing_m = 0.5;
  s.region = Eigen::Vector4d(3.0, 0.0, 7.0, 4.0);
  const auto table = planner::PostureTable::build(k70, s);
  ASSERT_EQ(table.pattern_count(), 1);
  ASSERT_GT(table.grid().nodes(), 30);
  planner::PtpPlanner ptp(k70, table, {});
  EXPECT_EQ(ptp.energy(), planner::PtpEnergy::kLoadSensing);
  const auto plan = ptp.plan({4.0, 1.0}, {6.5, 3.5}, W(1.0, 0.0, 0.0));
  ASSERT_TRUE(plan.path.found);
  EXPECT_GT(plan.energy_j, 0.0);
  EXPECT_GT(plan.path.steps.size(), 4u);
  const auto d = ptp.search(plan.path.steps.front().node, plan.path.steps.back().node,
                            W(1.0, 0.0, 0.0), planner::PtpSearch::kDijkstra);
  EXPECT_NEAR(d.cost, plan.path.cost, 1e-9 * d.cost);
}

TEST(JointTrajectoryModes, RoundTripAndErrors) {
  input::JointTrajectory t(2);
  const Eigen::Vector2d z = Eigen::Vector2d::Zero();
  t.append(0.0, z, z, z, {0, 1});
  t.append(0.5, Eigen::Vector2d(0.1, 0.2), z, z, {2, 0});
  EXPECT_THROW(t.append(1.0, z, z, z), std::invalid_argument);
  std::ostringstream out;
  input::write_joint_trajectory(out, t);
  EXPECT_NE(out.str().find("qddot_2,mode_1,mode_2\n"), std::string::npos);
  const auto back = input::JointTrajectory::parse(out.str(), "modes.csv");
  ASSERT_TRUE(back.has_modes());
  EXPECT_EQ(back.mode(1, 0), 2);
  EXPECT_EQ(back.mode(0, 1), 1);
  // Without mode columns as before.
  const auto plain = input::JointTrajectory::parse("t,q_1,qdot_1,qddot_1\n0,1,0,0\n", "p.csv");
  EXPECT_FALSE(plain.has_modes());
  try {
    input::JointTrajectory::parse(
        "t,q_1,q_2,qdot_1,qdot_2,qddot_1,qddot_2,mode_1\n0,0,0,0,0,0,0,1\n", "half.csv");
    ADD_FAILURE() << "a partial set of mode columns was accepted";
  } catch (const input::FileError& e) {
    EXPECT_NE(std::string(e.what()).find("half.csv:1: expected the header "
                                         "'t,q_1,q_2,qdot_1,qdot_2,qddot_1,qddot_2,mode_1,mode_2'"),
              std::string::npos)
        << e.what();
  }
  try {
    input::JointTrajectory::parse("t,q_1,qdot_1,qddot_1,mode_1\n0,0,0,0,1.5\n", "frac.csv");
    ADD_FAILURE() << "mode 1.5 was accepted";
  } catch (const input::FileError& e) {
    EXPECT_NE(std::string(e.what()).find("frac.csv:2: field 'mode_1'"), std::string::npos)
        << e.what();
  }
}

}  // namespace
