// Kinematics, cylinder geometry and the non-redundant IK, checked against the paper's closed form
// and against finite differences.
#include <gtest/gtest.h>

#include <random>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/inverse_kinematics.hpp"
#include "craneassist/dynamics/kinematics.hpp"

using namespace craneassist::dynamics;

namespace {

const CraneModel& k70m() {
  static const CraneModel model = craneassist::config::default_crane_config().model;
  return model;
}

JointVector random_q(const CraneModel& m, std::mt19937& rng) {
  JointVector q(m.dof());
  for (int i = 0; i < m.dof(); ++i) {
    std::uniform_real_distribution<double> d(m.joints[i].q_min, m.joints[i].q_max);
    q[i] = d(rng);
  }
  return q;
}

// check(q, jac, data) at `trials` random poses q of m (the generator seeded with seed), jac the tip
// Jacobian there; data for further kinematics.
template <class Check>
void at_random_poses(const CraneModel& m, unsigned seed, int trials, Check check) {
  std::mt19937 rng(seed);
  KinematicsData data;
  TaskJacobian jac;
  for (int trial = 0; trial < trials; ++trial) {
    const JointVector q = random_q(m, rng);
    tip_jacobian(m, data, q, jac);
    check(q, jac, data);
  }
}

}  // namespace

TEST(Kinematics, TipMatchesPaperClosedForm) {
  const auto& m = k70m();
  std::mt19937 rng(1);
  KinematicsData data;
  for (int trial = 0; trial < 50; ++trial) {
    const JointVector q = random_q(m, rng);
    const double l1 = 3.504, l2 = 0.376, l3 = 2.13, ox = -0.208, oy = 1.605;
    const double rho =
        l1 * std::cos(q[1]) - l2 * std::sin(q[1] + q[2]) + (l3 + q[3]) * std::cos(q[1] + q[2]) + ox;
    const Eigen::Vector3d expected(
        std::cos(q[0]) * rho,
        l1 * std::sin(q[1]) + l2 * std::cos(q[1] + q[2]) + (l3 + q[3]) * std::sin(q[1] + q[2]) + oy,
        std::sin(q[0]) * rho);
    EXPECT_LT((tip_position(m, data, q) - expected).norm(), 1e-12);
  }
}

TEST(Kinematics, ReachAtFullExtensionIsAbout9_1m) {
  const auto& m = k70m();
  KinematicsData data;
  double best = 0.0;
  JointVector q(4);
  q << 0.0, 0.0, 0.0, m.joints[3].q_max;
  for (double q2 = m.joints[1].q_min; q2 <= m.joints[1].q_max; q2 += 0.002) {
    for (double q3 = m.joints[2].q_min; q3 <= m.joints[2].q_max; q3 += 0.002) {
      q[1] = q2;
      q[2] = q3;
      const Eigen::Vector3d tip = tip_position(m, data, q);
      best = std::max(best, std::hypot(tip.x(), tip.z()));
    }
  }
  EXPECT_NEAR(best, 9.1, 0.15) << "horizontal reach from the slew axis";
}

TEST(Kinematics, JacobianMatchesFiniteDifferences) {
  for (const auto* model : {&k70m()}) {
    const auto& m = *model;
    at_random_poses(m, 2, 30,
                    [&](const JointVector& q, const TaskJacobian& jac, KinematicsData& data) {
                      for (int i = 0; i < m.dof(); ++i) {
                        const double h = 1e-6;
                        JointVector qp = q, qm = q;
                        qp[i] += h;
                        qm[i] -= h;
                        const Eigen::Vector3d fd =
                            (tip_position(m, data, qp) - tip_position(m, data, qm)) / (2 * h);
                        EXPECT_LT((jac.col(i) - fd).norm(), 1e-7) << "joint " << i;
                      }
                    });
  }
}

TEST(Kinematics, JacobianDotMatchesFiniteDifferences) {
  const auto planar = craneassist::config::planar_2r_config().model;
  for (const auto* model : {&k70m(), &planar}) {
    const auto& m = *model;
    std::mt19937 rng(3);
    std::normal_distribution<double> nd(0.0, 0.5);
    KinematicsData data;
    TaskJacobian jp, jm, jdot;
    for (int trial = 0; trial < 30; ++trial) {
      const JointVector q = random_q(m, rng);
      JointVector qdot(m.dof());
      for (int i = 0; i < m.dof(); ++i) qdot[i] = nd(rng);
      tip_jacobian_dot(m, data, q, qdot, jdot);
      const double h = 1e-6;
      tip_jacobian(m, data, q + h * qdot, jp);
      tip_jacobian(m, data, q - h * qdot, jm);
      const TaskJacobian fd = (jp - jm) / (2 * h);
      EXPECT_LT((jdot - fd).norm(), 1e-7);
    }
  }
}

TEST(Cylinders, RangesMatchTheReferenceCrane) {
  const auto& m = k70m();
  const auto& lift = m.cylinders[1];
  EXPECT_NEAR(cylinder_length(lift, m.joints[1].q_min), 1.081, 1e-3);
  EXPECT_NEAR(cylinder_length(lift, m.joints[1].q_max), 1.688, 1e-3);
  const auto& tilt = m.cylinders[2];
  EXPECT_NEAR(cylinder_length(tilt, -2.75), 1.875, 1e-3);
  EXPECT_NEAR(cylinder_length(tilt, -0.25), 1.150, 1e-3);
  double r2_min = 1e9, r2_max = 0, r3_min = 1e9, r3_max = 0;
  for (int k = 0; k <= 200; ++k) {
    const double q2 = m.joints[1].q_min + (m.joints[1].q_max - m.joints[1].q_min) * k / 200.0;
    const double q3 = m.joints[2].q_min + (m.joints[2].q_max - m.joints[2].q_min) * k / 200.0;
    r2_min = std::min(r2_min, cylinder_arm(lift, q2));
    r2_max = std::max(r2_max, cylinder_arm(lift, q2));
    EXPECT_LT(cylinder_arm(tilt, q3), 0.0) << "tilt cylinder shortens as q3 grows";
    r3_min = std::min(r3_min, -cylinder_arm(tilt, q3));
    r3_max = std::max(r3_max, -cylinder_arm(tilt, q3));
  }
  EXPECT_NEAR(r2_min, 0.318, 2e-3);
  EXPECT_NEAR(r2_max, 0.440, 2e-3);
  EXPECT_NEAR(r3_min, 0.252, 2e-3);
  EXPECT_NEAR(r3_max, 0.312, 2e-3);
  EXPECT_DOUBLE_EQ(cylinder_arm(m.cylinders[3], 1.0), 0.5);
  EXPECT_NEAR(cylinder_arm(m.cylinders[0], 0.0) * 2 * M_PI, 0.720, 1e-4);
}

TEST(Cylinders, ArmAndSlopeMatchFiniteDifferences) {
  const auto& m = k70m();
  for (int i = 0; i < m.dof(); ++i) {
    const auto& c = m.cylinders[i];
    for (int k = 1; k < 20; ++k) {
      const double q = m.joints[i].q_min + (m.joints[i].q_max - m.joints[i].q_min) * k / 20.0;
      const double h = 1e-6;
      EXPECT_NEAR(cylinder_arm(c, q),
                  (cylinder_length(c, q + h) - cylinder_length(c, q - h)) / (2 * h), 1e-8);
      EXPECT_NEAR(cylinder_arm_slope(c, q),
                  (cylinder_arm(c, q + h) - cylinder_arm(c, q - h)) / (2 * h), 1e-6);
    }
  }
}

TEST(Cylinders, PumpFlowUsesDirectionAndDifferentialSpool) {
  const auto& m = k70m();
  JointVector v(4);
  v << 0.0, 0.1, -0.1, 0.2;
  const double expected = 0.1 * m.cylinders[1].area_a_m2 + 0.1 * m.cylinders[2].area_b_m2 +
                          0.2 * (m.cylinders[3].area_a_m2 - m.cylinders[3].area_b_m2);
  EXPECT_NEAR(pump_flow_demand(m, v), expected, 1e-15);
}

TEST(InverseKinematics, RecoversJointsGivenExtension) {
  const auto& m = k70m();
  ASSERT_TRUE(is_loader_structure(m));
  std::mt19937 rng(4);
  KinematicsData data;
  int solved = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const JointVector q = random_q(m, rng);
    const Eigen::Vector3d tip = tip_position(m, data, q);
    JointVector q_ik;
    const IkStatus status = solve_given_extension(m, tip, q[3], q_ik);
    // The solver puts the tip in front of the slew axis (rho > 0); a pose reaching back over
    // the pillar has the same tip from the opposite bearing, a different but valid solution.
    const double rho = std::cos(q[0]) * tip.x() + std::sin(q[0]) * tip.z();
    if (rho < 0.5) continue;
    ASSERT_NE(status, IkStatus::kUnreachable);
    EXPECT_LT((tip_position(m, data, q_ik) - tip).norm(), 1e-9);
    // Folded-down tilt is the branch inside the joint ranges, so it is the original pose.
    if (status == IkStatus::kOk) {
      EXPECT_LT((q_ik - q).norm(), 1e-8);
      ++solved;
    }
  }
  EXPECT_GT(solved, 150);
  JointVector q_out;
  EXPECT_EQ(solve_given_extension(m, Eigen::Vector3d(20, 0, 0), 0.0, q_out),
            IkStatus::kUnreachable);
}

TEST(InverseKinematics, RatesGivenExtensionMeetTheTipVelocity) {
  at_random_poses(k70m(), 5, 50, [](const JointVector&, const TaskJacobian& jac, KinematicsData&) {
    const Eigen::Vector3d v(0.3, -0.2, 0.1);
    JointVector qdot;
    if (resolve_rates_given_extension(jac, v, 0.05, qdot) != IkStatus::kOk) return;
    EXPECT_LT((jac * qdot - v).norm(), 1e-10);
    EXPECT_DOUBLE_EQ(qdot[3], 0.05);
  });
}
