// The offline redundancy planner: the stage model's polynomial terms against an independent
// evaluation (inverse kinematics, Jacobians, recursive Newton-Euler), and the dynamic program
// against the online resolutions driven along the same path and judged by the same cost.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <atomic>
#include <cmath>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/inverse_kinematics.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/planner/dp_planner.hpp"
#include "rnea_reference.hpp"

namespace {

using namespace craneassist;
using craneassist::planner::PlanCost;

const dynamics::CraneModel& k70m() {
  static const dynamics::CraneModel model = config::default_crane_config().model;
  return model;
}

// A straight rest-to-rest quintic from a to b in duration_s, sampled every dt_s.
planner::TipSamples quintic(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double duration_s,
                            double dt_s) {
  planner::TipSamples s;
  s.dt_s = dt_s;
  const int n = static_cast<int>(std::lround(duration_s / dt_s));
  for (int k = 0; k <= n; ++k) {
    const double x = k * dt_s / duration_s, x2 = x * x, x3 = x2 * x;
    const double f = x3 * (10 - 15 * x + 6 * x2);
    const double fd = 30 * x2 * (1 - 2 * x + x2) / duration_s;
    const double fdd = 60 * x * (1 - 3 * x + 2 * x2) / (duration_s * duration_s);
    s.p_m.push_back(a + (b - a) * f);
    s.v_m_s.push_back((b - a) * fd);
    s.a_m_s2.push_back((b - a) * fdd);
  }
  return s;
}

// A 4 s horizontal move of 1.6 m (peak 0.75 m/s), short enough for a quick test.
planner::TipSamples horizontal_move() {
  return quintic({3.2, 1.5, 1.0}, {4.8, 1.5, 1.0}, 4.0, 0.05);
}

TEST(StageModel, TermsMatchAnIndependentEvaluation) {
  const auto& m = k70m();
  const auto samples = horizontal_move();
  planner::StageModel stages(m, samples, {});
  dynamics::RigidBodyTerms terms(m);
  planner::PositionTerms pos;
  planner::VelocityTerms vel;
  dynamics::KinematicsData kin;
  dynamics::TaskJacobian jac, jdot;
  int checked = 0;
  for (int k : {10, 40, 55}) {
    for (double c : {0.2, 0.5, 0.8}) {
      stages.position_terms(k, c, terms, pos);
      ASSERT_TRUE(pos.reachable);
      for (double v : {-0.2, 0.05, 0.3}) {
        stages.velocity_terms(pos, v, vel);
        for (double a : {-0.3, 0.0, 0.25}) {
          const auto ku = static_cast<std::size_t>(k);
          // Independent: q from the IK, qdot and qddot from the tip equations, tau by RNEA.
          dynamics::JointVector q, qdot(4), qddot(4);
          ASSERT_EQ(dynamics::solve_given_extension(m, samples.p_m[ku], stages.q4_of(c), q),
                    dynamics::IkStatus::kOk);
          dynamics::tip_jacobian(m, kin, q, jac);
          const Eigen::Matrix3d j123 = jac.leftCols<3>();
          const double q4dot = v / stages.extension_arm(), q4ddot = a / stages.extension_arm();
          qdot << j123.inverse() * (samples.v_m_s[ku] - jac.col(3) * q4dot), q4dot;
          dynamics::tip_jacobian_dot(m, kin, q, qdot, jdot);
          qddot << j123.inverse() * (samples.a_m_s2[ku] - jdot * qdot - jac.col(3) * q4ddot),
              q4ddot;
          const dynamics::JointVector tau =
              craneassist::test::rnea(m, q, qdot, qddot, m.gravity_m_s2);

          dynamics::JointVector qddot_model;
          stages.joint_accelerations(pos, vel, a, qddot_model);
          EXPECT_LT((vel.qdot - qdot).norm(), 1e-9);
          EXPECT_LT((qddot_model - qddot).norm(), 1e-7 * (1 + qddot.norm()));
          for (int i = 0; i < 4; ++i) {
            const auto& cyl = m.cylinders[static_cast<std::size_t>(i)];
            const double arm = dynamics::cylinder_arm(cyl, q[i]);
            const double force = tau[i] / arm;
            const double acc =
                arm * qddot[i] + dynamics::cylinder_arm_slope(cyl, q[i]) * qdot[i] * qdot[i];
            EXPECT_NEAR(vel.force0[i] + vel.force1[i] * a, force, 1e-6 * (1.0 + std::abs(force)));
            EXPECT_NEAR(vel.acc0[i] + vel.acc1[i] * a, acc, 1e-7);
            EXPECT_NEAR(vel.v[i], arm * qdot[i], 1e-12);
          }
          ++checked;
        }
      }
    }
  }
  EXPECT_EQ(checked, 81);
}

TEST(StageModel, CostsFollowTheirDefinitions) {
  const auto& m = k70m();
  dynamics::RigidBodyTerms terms(m);
  planner::PositionTerms pos;
  planner::VelocityTerms vel;
  const double dt = 0.05;
  for (PlanCost cost : {PlanCost::kLoadSensing, PlanCost::kConstantPressure,
                        PlanCost::kActuatorEnergy, PlanCost::kExtension}) {
    planner::StageModelOptions options;
    options.cost = cost;
    planner::StageModel stages(m, horizontal_move(), options);
    stages.position_terms(30, 0.5, terms, pos);
    stages.velocity_terms(pos, 0.1, vel);
    const double a = 0.05;
    double flow = 0.0, p_max = 0.0, work = 0.0;
    for (int i = 0; i < 4; ++i) {
      const auto& cyl = m.cylinders[static_cast<std::size_t>(i)];
      const double v = vel.v[i], force = vel.force0[i] + vel.force1[i] * a;
      flow += dynamics::flow_area_m2(cyl, v) * std::abs(v);
      if (std::abs(v) > 1e-4) {
        p_max = std::max(p_max, std::copysign(1.0, v) * force / dynamics::flow_area_m2(cyl, v));
        work += std::max(force * v, 0.0);
      }
    }
    const auto got = stages.cost(vel, a);
    EXPECT_EQ(got.penalty, 0.0) << planner::to_string(cost);
    double expected = 0.0;
    switch (cost) {
      case PlanCost::kLoadSensing:
        expected = (p_max + m.pump.ls_margin_pa) * flow * dt;
        break;
      case PlanCost::kConstantPressure:
        expected = 20e6 * flow * dt;
        break;
      case PlanCost::kActuatorEnergy:
        expected = work * dt;
        break;
      case PlanCost::kExtension:
        expected = 0.1 * 0.1 * dt;
        break;
    }
    EXPECT_NEAR(got.cost, expected, 1e-9 * expected) << planner::to_string(cost);
    EXPECT_GT(got.cost, 0.0);
  }
}

TEST(StageModel, LimitsArePenalised) {
  const auto& m = k70m();
  planner::StageModel stages(m, horizontal_move(), {});
  dynamics::RigidBodyTerms terms(m);
  // Beyond the extension cylinder's velocity and acceleration limits.
  EXPECT_EQ(stages.evaluate(30, 0.5, 0.0, 0.0, terms).penalty, 0.0);
  EXPECT_EQ(stages.evaluate(30, 0.5, 0.1, 0.1, terms).penalty, 0.0);
  EXPECT_GT(stages.evaluate(30, 0.5, 1.2 * stages.v_max(), 0.0, terms).penalty,
            stages.options().penalty_factor * stages.stage_scale());
  EXPECT_GT(stages.evaluate(30, 0.5, 0.1, 1.5 * stages.a_max(), terms).penalty,
            stages.options().penalty_factor * stages.stage_scale());
  // Beyond the stroke.
  EXPECT_GT(stages.evaluate(30, stages.c_max() + 0.1, 0.0, 0.0, terms).penalty, 0.0);
}

planner::DpOptions test_grid() {
  planner::DpOptions o;
  o.grid = {120, 41, 61};
  o.refinement.passes = 3;
  return o;
}

double total(const planner::Plan& p) {
  return p.total_cost + p.total_penalty;
}

TEST(DpPlanner, NeverWorseThanTheOnlineResolutionsOnItsOwnCost) {
  const auto& m = k70m();
  for (PlanCost cost :
       {PlanCost::kLoadSensing, PlanCost::kConstantPressure, PlanCost::kActuatorEnergy}) {
    planner::StageModelOptions options;
    options.cost = cost;
    planner::StageModel stages(m, horizontal_move(), options);
    double c_lo = 0.0, c_hi = 0.0;
    ASSERT_TRUE(planner::feasible_extension_range(stages, 0, c_lo, c_hi));
    const auto dp = planner::plan_dp(stages, c_lo, test_grid());
    ASSERT_TRUE(dp.ok);
    EXPECT_EQ(dp.total_penalty, 0.0) << planner::to_string(cost);
    for (auto r : {dynamics::Resolution::kPinvJoint, dynamics::Resolution::kPinvActuator,
                   dynamics::Resolution::kMinFlow, dynamics::Resolution::kMinLsPower}) {
      const auto online = planner::plan_online(stages, r, c_lo);
      // The grid's resolution (the kinks of the flow where a cylinder comes to rest are resolved
      // to a few mm/s) is the only allowance: 0.5 %.
      EXPECT_LE(total(dp), 1.005 * total(online))
          << planner::to_string(cost) << " vs " << online.method;
    }
  }
}

TEST(DpPlanner, BeatsThePseudoInversesClearlyOnEnergy) {
  planner::StageModelOptions options;
  options.cost = PlanCost::kLoadSensing;
  planner::StageModel stages(k70m(), horizontal_move(), options);
  double c_lo = 0.0, c_hi = 0.0;
  ASSERT_TRUE(planner::feasible_extension_range(stages, 0, c_lo, c_hi));
  const auto dp = planner::plan_dp(stages, c_lo, test_grid());
  const auto pinv = planner::plan_online(stages, dynamics::Resolution::kPinvJoint, c_lo);
  EXPECT_LT(total(dp), 0.9 * total(pinv));
}

TEST(DpPlanner, ExtensionCostKeepsTheExtensionStill) {
  planner::StageModelOptions options;
  options.cost = PlanCost::kExtension;
  planner::StageModel stages(k70m(), horizontal_move(), options);
  const auto dp = planner::plan_dp(stages, 0.4, test_grid());
  ASSERT_TRUE(dp.ok);
  EXPECT_EQ(dp.total_penalty, 0.0);
  double v_max = 0.0;
  for (const auto& p : dp.points) v_max = std::max(v_max, std::abs(p.v_m_s));
  EXPECT_LT(v_max, 0.02);
}

TEST(DpPlanner, PlanFollowsTheTipPathAndRespectsLimits) {
  const auto& m = k70m();
  const auto samples = horizontal_move();
  planner::StageModel stages(m, samples, {});
  const auto dp = planner::plan_dp(stages, 0.3, test_grid());
  ASSERT_TRUE(dp.ok);
  ASSERT_EQ(dp.points.size(), samples.p_m.size());
  dynamics::KinematicsData kin;
  dynamics::TaskJacobian jac;
  for (std::size_t k = 0; k < dp.points.size(); ++k) {
    const auto& p = dp.points[k];
    EXPECT_LT((dynamics::tip_position(m, kin, p.q) - samples.p_m[k]).norm(), 1e-9);
    dynamics::tip_jacobian(m, kin, p.q, jac);
    EXPECT_LT((jac * p.qdot - samples.v_m_s[k]).norm(), 1e-9);
    for (int i = 0; i < 4; ++i) {
      const auto& cyl = m.cylinders[static_cast<std::size_t>(i)];
      const auto& joint = m.joints[static_cast<std::size_t>(i)];
      EXPECT_LE(std::abs(dynamics::cylinder_arm(cyl, p.q[i]) * p.qdot[i]), cyl.v_max_m_s + 1e-9);
      EXPECT_GE(p.q[i], joint.q_min);
      EXPECT_LE(p.q[i], joint.q_max);
    }
    EXPECT_LE(std::abs(p.a_m_s2), stages.a_max() + 1e-12);
  }
  EXPECT_NEAR(dp.points.back().v_m_s, 0.0, 0.01);  // at rest at the end, as the tip
}

TEST(DpPlanner, SameResultWithOneOrTwoThreads) {
  planner::StageModel stages(k70m(), horizontal_move(), {});
  auto one = test_grid();
  one.threads = 1;
  auto two = test_grid();
  two.threads = 2;
  const auto a = planner::plan_dp(stages, 0.3, one);
  const auto b = planner::plan_dp(stages, 0.3, two);
  ASSERT_TRUE(a.ok && b.ok);
  EXPECT_EQ(a.total_cost, b.total_cost);
  EXPECT_EQ(a.points.back().c_m, b.points.back().c_m);
}

TEST(DpPlanner, ReportsProgressAndCanBeCancelled) {
  planner::StageModel stages(k70m(), horizontal_move(), {});
  auto options = test_grid();
  options.refinement.passes = 0;
  std::atomic<bool> cancel{false};
  int calls = 0, last_done = 0, in_all = 0;
  options.cancel = &cancel;
  options.progress = [&](int done, int all) {
    ++calls;
    last_done = done;
    in_all = all;
    if (done == 10) cancel = true;
  };
  const auto plan = planner::plan_dp(stages, 0.3, options);
  EXPECT_FALSE(plan.ok);
  EXPECT_EQ(last_done, 10);
  EXPECT_EQ(in_all, stages.stages());
  EXPECT_EQ(calls, 10);
}

TEST(DpPlanner, CostToGoPredictsTheForwardCost) {
  planner::StageModel stages(k70m(), horizontal_move(), {});
  auto options = test_grid();
  options.refinement.passes = 0;
  const planner::DpSolution solution(stages, options);
  const auto plan = solution.forward(0.3);
  const double predicted = solution.cost_to_go(0, 0.3, 0.0);
  EXPECT_NEAR(total(plan), predicted, 0.03 * predicted);
}

TEST(DpPlanner, RejectsAModelWithoutTheLoaderStructure) {
  const auto planar = config::planar_2r_config().model;
  EXPECT_THROW(planner::StageModel(planar, horizontal_move(), {}), std::invalid_argument);
}

}  // namespace
