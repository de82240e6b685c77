// The online redundancy resolutions: each meets the tip task exactly and its own optimality
// condition (never beaten by a fine sweep of the extension rate), within the joint-rate bounds.
#include <gtest/gtest.h>

#include <random>
#include <utility>
#include <vector>

#include "craneassist/dynamics/resolutions.hpp"
#include "random_tip_task.hpp"

using namespace craneassist::dynamics;

namespace {

using craneassist::test::k70m;
using Case = craneassist::test::RandomTipTask;

Case random_case(std::mt19937& rng) {
  return craneassist::test::random_tip_task(rng, 0.5);
}

bool well_conditioned(const Case& c) {
  return std::abs(Eigen::Matrix3d(c.jacobian.leftCols<3>()).determinant()) > 1e-2;
}

// The well-conditioned ones of `trials` random cases drawn from a generator seeded with seed.
std::vector<Case> well_conditioned_cases(unsigned seed, int trials) {
  std::mt19937 rng(seed);
  std::vector<Case> out;
  for (int trial = 0; trial < trials; ++trial) {
    Case c = random_case(rng);
    if (well_conditioned(c)) out.push_back(std::move(c));
  }
  return out;
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
  int checked = 0;
  for (const Case& c : well_conditioned_cases(11, 200)) {
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
  for (const Case& c : well_conditioned_cases(12, 100)) {
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
  int checked = 0;
  for (const Case& c : well_conditioned_cases(13, 100)) {
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
  for (const Case& c : well_conditioned_cases(14, 100)) {
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
