// The online redundancy resolutions: each meets the tip task exactly and its own optimality
// condition (never beaten by a fine sweep of the extension rate), within the joint-rate bounds.
#include <gtest/gtest.h>

#include <random>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/resolutions.hpp"

using namespace craneassist::dynamics;

namespace {

const CraneModel& k70m() {
  static const CraneModel model = craneassist::config::default_crane_config().model;
  return model;
}

struct Case {
  JointVector q;
  TaskJacobian jacobian;
  Eigen::Vector3d v;
  JointVector arms;
  JointVector force;
};

Case random_case(std::mt19937& rng) {
  const auto& m = k70m();
  Case c;
  c.q.resize(4);
  for (int i = 0; i < 4; ++i) {
    std::uniform_real_distribution<double> d(m.joints[i].q_min + 0.05, m.joints[i].q_max - 0.05);
    c.q[i] = d(rng);
  }
  KinematicsData kin;
  tip_jacobian(m, kin, c.q, c.jacobian);
  std::normal_distribution<double> nd(0.0, 0.5);
  c.v = Eigen::Vector3d(nd(rng), nd(rng), nd(rng));
  cylinder_arms(m, c.q, c.arms);
  std::normal_distribution<double> force(0.0, 5e4);
  c.force.resize(4);
  for (int i = 0; i < 4; ++i) c.force[i] = force(rng);
  return c;
}

bool well_conditioned(const Case& c) {
  return std::abs(Eigen::Matrix3d(c.jacobian.leftCols<3>()).determinant()) > 1e-2;
}

const JointRateBounds kLoose{JointVector::Constant(4, -1e3), JointVector::Constant(4, 1e3)};

ExtensionResolutionResult solve(Resolution r, const Case& c, const JointRateBounds& bounds) {
  ExtensionResolutionInput in;
  in.jacobian = &c.jacobian;
  in.v_tip = c.v;
  in.dc_dq = &c.arms;
  in.bounds = &bounds;
  in.cylinder_force = &c.force;
  ExtensionResolutionResult out;
  resolve_by_extension(k70m(), r, in, out);
  return out;
}

}  // namespace

TEST(Resolutions, EveryResolutionMeetsTheTipTask) {
  std::mt19937 rng(11);
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Case c = random_case(rng);
    if (!well_conditioned(c)) continue;
    for (Resolution r :
         {Resolution::kPinvActuator, Resolution::kMinFlow, Resolution::kMinLsPower}) {
      const auto out = solve(r, c, kLoose);
      ASSERT_TRUE(out.feasible);
      EXPECT_LT((c.jacobian * out.qdot - c.v).norm(), 1e-9 * (1.0 + c.v.norm()));
      EXPECT_DOUBLE_EQ(out.qdot[3], out.extension_rate);
    }
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST(Resolutions, PinvActuatorIsTheWeightedPseudoInverse) {
  std::mt19937 rng(12);
  for (int trial = 0; trial < 100; ++trial) {
    const Case c = random_case(rng);
    if (!well_conditioned(c)) continue;
    // min |R qdot|^2 subject to J qdot = v: qdot = W^-1 J^T (J W^-1 J^T)^-1 v, W = R^2.
    const Eigen::Vector4d w_inv = c.arms.cwiseProduct(c.arms).cwiseInverse();
    const Eigen::Matrix<double, 3, 4> j = c.jacobian;
    const Eigen::Matrix<double, 4, 3> jw = w_inv.asDiagonal() * j.transpose();
    const Eigen::Vector4d expected = jw * (j * jw).inverse() * c.v;
    const auto out = solve(Resolution::kPinvActuator, c, kLoose);
    EXPECT_LT((out.qdot - JointVector(expected)).norm(), 1e-9 * (1.0 + expected.norm()));
  }
}

TEST(Resolutions, MinFlowAndMinLsPowerAreNeverBeatenByASweep) {
  std::mt19937 rng(13);
  int checked = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const Case c = random_case(rng);
    if (!well_conditioned(c)) continue;
    // A box of joint-rate bounds, so the extension-rate interval is finite.
    const JointRateBounds bounds{JointVector::Constant(4, -0.8), JointVector::Constant(4, 0.8)};
    for (Resolution r : {Resolution::kMinFlow, Resolution::kMinLsPower}) {
      const auto best = solve(r, c, bounds);
      if (!best.feasible) continue;
      // Sweep the extension rate finely over the feasible interval.
      const Eigen::Matrix3d j123 = c.jacobian.leftCols<3>();
      for (int k = 0; k <= 4000; ++k) {
        const double t = -0.8 + 1.6 * k / 4000.0;
        JointVector qdot(4);
        qdot << j123.inverse() * (c.v - c.jacobian.col(3) * t), t;
        if ((qdot.array() < -0.8).any() || (qdot.array() > 0.8).any()) continue;
        const double cost = resolution_cost(k70m(), r, qdot, c.arms, &c.force);
        ASSERT_GE(cost, best.cost - 1e-9 * (1.0 + best.cost))
            << to_string(r) << " beaten at t = " << t << " (best t = " << best.extension_rate
            << ")";
      }
      for (int i = 0; i < 4; ++i) {
        EXPECT_GE(best.qdot[i], -0.8 - 1e-12);
        EXPECT_LE(best.qdot[i], 0.8 + 1e-12);
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 50);
}

TEST(Resolutions, MinFlowNeedsNoMoreFlowThanThePseudoInverses) {
  std::mt19937 rng(14);
  for (int trial = 0; trial < 100; ++trial) {
    const Case c = random_case(rng);
    if (!well_conditioned(c)) continue;
    const auto min_flow = solve(Resolution::kMinFlow, c, kLoose);
    const auto actuator = solve(Resolution::kPinvActuator, c, kLoose);
    EXPECT_LE(
        min_flow.cost,
        resolution_cost(k70m(), Resolution::kMinFlow, actuator.qdot, c.arms, nullptr) + 1e-12);
  }
}

TEST(Resolutions, InfeasibleBoundsAreReported) {
  std::mt19937 rng(15);
  Case c = random_case(rng);
  while (!well_conditioned(c)) c = random_case(rng);
  c.v = Eigen::Vector3d(5.0, 5.0, 5.0);  // far more than tiny rate bounds allow
  const JointRateBounds tiny{JointVector::Constant(4, -1e-3), JointVector::Constant(4, 1e-3)};
  const auto out = solve(Resolution::kMinFlow, c, tiny);
  EXPECT_FALSE(out.feasible);
  EXPECT_EQ(out.qdot.norm(), 0.0);
}
