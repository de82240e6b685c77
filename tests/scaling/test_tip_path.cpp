// scaling::TipPath on its own (test_tip_scaler.cpp runs it with the TipScaler): on the K70M,
// for every resolution and directions all round, f' moves the tip exactly along u, f'' is the
// derivative of f' along the path, a joint at an end is never driven into it (or the direction is
// held at zero speed), and from the edge of the workspace moving back is not limited.
#include <gtest/gtest.h>

#include <cmath>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/scaling/tip_path.hpp"

using namespace craneassist;
using dynamics::JointVector;

namespace {

class TipPathTest : public ::testing::TestWithParam<dynamics::Resolution> {
 protected:
  TipPathTest() : cfg_(config::default_crane_config()) {}

  scaling::TipPathConfig path_config() const {
    scaling::TipPathConfig c;
    c.jerk_max = cfg_.scaling.jerk_max_m_s3;
    c.deceleration_max = cfg_.scaling.deceleration_max_m_s2;
    c.flow_reserve = cfg_.control.flow_reserve;
    c.resolution = GetParam();
    return c;
  }

  // What a fresh tip path finds at q for the direction u, heading for intended_speed from rest.
  scaling::TipPathOutput first_output(const JointVector& q, const Eigen::Vector3d& u,
                                      double intended_speed) const {
    scaling::TipPath path(cfg_.model, path_config());
    scaling::TipPathInput in;
    in.direction = u;
    in.intended_speed = intended_speed;
    scaling::TipPathOutput out;
    path.update(q, in, out);
    return out;
  }

  Eigen::Vector3d tip_velocity(const JointVector& q, const JointVector& qdot) {
    dynamics::tip_jacobian(cfg_.model, kin_, q, jac_);
    return jac_ * qdot;
  }

  config::CraneConfig cfg_;
  dynamics::KinematicsData kin_;
  dynamics::TaskJacobian jac_;
};

// Unit directions all round: the six axes and the eight diagonals.
std::vector<Eigen::Vector3d> directions() {
  std::vector<Eigen::Vector3d> out;
  for (int a = 0; a < 3; ++a) {
    for (double s : {-1.0, 1.0}) out.push_back(s * Eigen::Vector3d::Unit(a));
  }
  for (double x : {-1.0, 1.0}) {
    for (double y : {-1.0, 1.0}) {
      for (double z : {-1.0, 1.0}) out.push_back(Eigen::Vector3d(x, y, z).normalized());
    }
  }
  return out;
}

}  // namespace

TEST_P(TipPathTest, TangentMovesTheTipExactlyAlongTheDirection) {
  const JointVector q = cfg_.simulation.q_initial;
  for (const Eigen::Vector3d& u : directions()) {
    const scaling::TipPathOutput out = first_output(q, u, 0.5);
    ASSERT_TRUE(out.geometry.f1.allFinite());
    const Eigen::Vector3d v = tip_velocity(q, out.geometry.f1);
    EXPECT_LT((v - u).norm(), 1e-9) << "u " << u.transpose() << " tip " << v.transpose();
  }
}

TEST_P(TipPathTest, SecondDerivativeIsTheChangeOfTheTangentAlongThePath) {
  // One step of h along the path: f'(q + f' h) ~ f' + f'' h (a fresh TipPath each time, so no
  // smoothing window between the two).
  const JointVector q = cfg_.simulation.q_initial;
  const double h = 1e-3;
  for (const Eigen::Vector3d& u : directions()) {
    const scaling::TipPathOutput a = first_output(q, u, 0.3);
    const JointVector q_next = q + a.geometry.f1 * h;
    const scaling::TipPathOutput b = first_output(q_next, u, 0.3);
    const JointVector predicted = a.geometry.f1 + a.geometry.f2 * h;
    const double scale = 1.0 + a.geometry.f2.norm();
    EXPECT_LT((b.geometry.f1 - predicted).norm(), 1e-3 * scale) << "u " << u.transpose();
  }
}

TEST_P(TipPathTest, AJointAtItsEndIsNeverDrivenIntoIt) {
  // The tilt at its lower end. Every direction either resolves without moving it further down,
  // or is one the other joints cannot do (the edge of the workspace along it): then the end
  // damping holds the path speed at zero, so the tip does not move that way at all.
  JointVector q = cfg_.simulation.q_initial;
  const auto& tilt = cfg_.model.joints[2];
  q[2] = tilt.q_min;
  int movable = 0;
  for (const Eigen::Vector3d& u : directions()) {
    const scaling::TipPathOutput out = first_output(q, u, 0.5);
    if (out.sdot_joint_limit > 0.0) {
      ++movable;
      EXPECT_GE(out.geometry.f1[2], -1e-12) << "u " << u.transpose();
    } else {
      EXPECT_EQ(out.status, dynamics::NullSpaceStatus::kPositionLimit) << "u " << u.transpose();
    }
  }
  EXPECT_GE(movable, 7) << "most directions remain possible with the tilt at its end";
}

TEST_P(TipPathTest, EndDampingFallsTowardsTheEdgeAndNeverLimitsMovingBack) {
  // Reach straight out from the start pose, moving the reference along f' until the end damping
  // has fallen to a crawl (the edge of the workspace straight out); from there the way back in is
  // not limited. (That the path speed never dips on the way, while joints hand over, is
  // TipMotion.NoSlowDownForAJointEnd's.)
  JointVector q = cfg_.simulation.q_initial;
  const Eigen::Vector3d out_dir = Eigen::Vector3d::UnitX();
  scaling::TipPath path(cfg_.model, path_config());
  scaling::TipPathInput in;
  in.direction = out_dir;
  in.intended_speed = 0.5;
  in.sdot = 0.5;
  scaling::TipPathOutput out;
  bool reached_edge = false;
  for (int k = 0; k < 20000 && !reached_edge; ++k) {
    path.update(q, in, out);
    EXPECT_LT((tip_velocity(q, out.geometry.f1) - out_dir).norm(), 1e-6) << k;
    reached_edge = out.sdot_joint_limit < 0.02;
    q += out.geometry.f1 * 0.002;  // 2 mm of tip path
  }
  ASSERT_TRUE(reached_edge) << "the workspace ends somewhere straight out";
  scaling::TipPath back(cfg_.model, path_config());
  in.direction = -out_dir;
  in.sdot = 0.0;
  back.update(q, in, out);
  EXPECT_GT(out.sdot_joint_limit, 0.5) << "moving back in is not limited";
  EXPECT_LT((tip_velocity(q, out.geometry.f1) + out_dir).norm(), 1e-6);
}

INSTANTIATE_TEST_SUITE_P(EveryResolution, TipPathTest,
                         ::testing::Values(dynamics::Resolution::kPinvJoint,
                                           dynamics::Resolution::kPinvActuator,
                                           dynamics::Resolution::kMinFlow,
                                           dynamics::Resolution::kMinLsPower),
                         [](const auto& param_info) {
                           std::string name = dynamics::to_string(param_info.param);
                           for (char& c : name) {
                             if (c == '-') c = '_';
                           }
                           return name;
                         });
