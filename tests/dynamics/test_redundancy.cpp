// SNS joint-limited pseudo-inverse and the joint-rate bounds.
#include <gtest/gtest.h>

#include <random>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/redundancy.hpp"

using namespace craneassist::dynamics;

namespace {

const CraneModel& k70m() {
  static const CraneModel model = craneassist::config::default_crane_config().model;
  return model;
}

JointRateBounds loose(int n) {
  return {JointVector::Constant(n, -100.0), JointVector::Constant(n, 100.0)};
}

double angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

}  // namespace

TEST(Sns, UnconstrainedIsTheMinimumNormSolution) {
  KinematicsData data;
  TaskJacobian jac;
  JointVector q = craneassist::config::default_crane_config().simulation.q_initial;
  tip_jacobian(k70m(), data, q, jac);
  const Eigen::Vector3d v(0.3, -0.2, 0.5);
  SnsResult r;
  sns_velocity_ik(jac, v, loose(4), r);
  EXPECT_DOUBLE_EQ(r.task_scale, 1.0);
  EXPECT_EQ(r.saturated_joints, 0);
  EXPECT_LT((jac * r.qdot - v).norm(), 1e-12);
  const Eigen::Matrix<double, 4, 3> pinv = jac.transpose() * (jac * jac.transpose()).inverse();
  EXPECT_LT((r.qdot - pinv * v).norm(), 1e-12);
}

TEST(Sns, SaturatesAJointAndMeetsTheTaskWithTheOthers) {
  KinematicsData data;
  TaskJacobian jac;
  JointVector q = craneassist::config::default_crane_config().simulation.q_initial;
  tip_jacobian(k70m(), data, q, jac);
  const Eigen::Vector3d v(0.5, 0.0, 0.0);
  SnsResult free_result;
  sns_velocity_ik(jac, v, loose(4), free_result);
  ASSERT_GT(free_result.qdot[3], 0.05) << "the extension takes part in reaching out";
  // The extension may not move: the other three joints do the whole task.
  JointRateBounds b = loose(4);
  b.lower[3] = 0.0;
  b.upper[3] = 0.0;
  SnsResult r;
  sns_velocity_ik(jac, v, b, r);
  EXPECT_DOUBLE_EQ(r.task_scale, 1.0);
  EXPECT_EQ(r.saturated_joints, 1);
  EXPECT_DOUBLE_EQ(r.qdot[3], 0.0);
  EXPECT_LT((jac * r.qdot - v).norm(), 1e-12);
}

TEST(Sns, InfeasibleTaskIsScaledAlongItsDirection) {
  KinematicsData data;
  TaskJacobian jac;
  std::mt19937 rng(7);
  for (int trial = 0; trial < 100; ++trial) {
    JointVector q(4);
    for (int i = 0; i < 4; ++i) {
      std::uniform_real_distribution<double> d(k70m().joints[i].q_min + 0.1,
                                               k70m().joints[i].q_max - 0.1);
      q[i] = d(rng);
    }
    tip_jacobian(k70m(), data, q, jac);
    std::normal_distribution<double> nd(0.0, 1.0);
    const Eigen::Vector3d v(nd(rng), nd(rng), nd(rng));
    const JointRateBounds b{JointVector::Constant(4, -0.05), JointVector::Constant(4, 0.05)};
    SnsResult r;
    sns_velocity_ik(jac, v, b, r);
    for (int i = 0; i < 4; ++i) {
      EXPECT_GE(r.qdot[i], b.lower[i] - 1e-9);
      EXPECT_LE(r.qdot[i], b.upper[i] + 1e-9);
    }
    EXPECT_LE(r.task_scale, 1.0);
    if (r.task_scale > 1e-6) {
      EXPECT_LT((jac * r.qdot - r.task_scale * v).norm(), 1e-7 * v.norm()) << "trial " << trial;
      EXPECT_LT(angle(jac * r.qdot, v), 1e-6);
    }
  }
}

TEST(JointRateBounds, StopAtTheLimitWithinTheAcceleration) {
  const auto& m = k70m();
  JointVector q(4);
  q << 0.0, m.joints[1].q_max, -1.0, 0.02;  // lift at its upper end, extension 2 cm from 0
  const JointVector vmax = JointVector::Constant(4, 1.0);
  const JointVector amax = JointVector::Constant(4, 0.5);
  JointRateBounds b;
  joint_rate_bounds(m, q, vmax, amax, 0.01, b);
  EXPECT_DOUBLE_EQ(b.upper[1], 0.0);
  EXPECT_LT(b.lower[1], 0.0);
  EXPECT_NEAR(b.lower[3], -std::sqrt(2 * 0.5 * 0.02), 1e-12);
  EXPECT_DOUBLE_EQ(b.upper[0], 1.0);
}
