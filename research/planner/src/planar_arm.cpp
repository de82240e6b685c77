#include "craneassist/planner/planar_arm.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/static_gravity.hpp"

namespace craneassist::planner {
namespace {

using dynamics::JointType;

std::size_t at(int i) {
  return static_cast<std::size_t>(i);
}

// The crane-frame axis of joint i (z of DH frame i - 1) at q.
Eigen::Vector3d joint_axis(const dynamics::CraneModel& model, dynamics::KinematicsData& data,
                           const dynamics::JointVector& q, int i) {
  dynamics::forward_kinematics(model, data, q);
  return model.task_from_base * data.frames[at(i)].linear().col(2);
}

}  // namespace

PlanarArm::PlanarArm(const dynamics::CraneModel& model, const dynamics::JointVector& q_hold)
    : model_(&model), q_hold_(q_hold) {
  const int n = model.dof();
  if (q_hold.size() != n) throw std::invalid_argument("PlanarArm: posture of the wrong size");
  const Eigen::Vector3d g = model.task_from_base * model.gravity_m_s2;
  if (!(g.norm() > 0.0)) throw std::invalid_argument("the crane has no gravity to plan against");
  const Eigen::Vector3d up = -g.normalized();
  dynamics::KinematicsData data;
  // A slewing crane: the first joint turns about the vertical.
  int first = 0;
  if (n >= 3 && model.joints[0].type == JointType::kRevolute &&
      joint_axis(model, data, q_hold, 0).cross(up).norm() < 1e-9) {
    first = 1;
  }
  for (int i = first; i < n; ++i) active_.push_back(i);
  // The plane's normal: the first moving revolute joint's axis, which must be horizontal; every
  // other revolute axis parallel to it, every prismatic axis in the plane.
  bool found = false;
  for (int i : active_) {
    const Eigen::Vector3d axis = joint_axis(model, data, q_hold, i);
    if (model.joints[at(i)].type == JointType::kRevolute) {
      if (!found) {
        normal_ = axis;
        found = true;
      } else if (axis.cross(normal_).norm() > 1e-9) {
        throw std::invalid_argument("the joint axes are not parallel: not a planar arm");
      }
    }
  }
  if (!found || std::abs(normal_.dot(up)) > 1e-9) {
    throw std::invalid_argument("the arm does not move in a vertical plane");
  }
  Eigen::Vector3d x_axis = up.cross(normal_).normalized();
  // X points outwards: the tip at q_hold is on its positive side (seen from the first moving
  // joint's axis).
  dynamics::forward_kinematics(model, data, q_hold);
  const Eigen::Vector3d base = model.task_from_base * data.frames[at(active_[0])].translation();
  const Eigen::Vector3d tip = model.task_from_base * data.frames[at(n)].translation();
  if (x_axis.dot(tip - base) < 0.0) {
    x_axis = -x_axis;
    normal_ = -normal_;
  }
  plane_.row(0) = x_axis.transpose();
  plane_.row(1) = up.transpose();
  normal_offset_ = normal_.dot(tip);
  for (int i : active_) {
    if (model.joints[at(i)].type == JointType::kPrismatic &&
        std::abs(joint_axis(model, data, q_hold, i).dot(normal_)) > 1e-9) {
      throw std::invalid_argument("a prismatic joint leaves the arm's plane");
    }
  }
}

double PlanarArm::lower(int k) const {
  return model_->joints[at(joint(k))].q_min;
}
double PlanarArm::upper(int k) const {
  return model_->joints[at(joint(k))].q_max;
}

dynamics::JointVector PlanarArm::full(const ArmVector& a) const {
  dynamics::JointVector q = q_hold_;
  for (int k = 0; k < moving(); ++k) q[joint(k)] = a[k];
  return q;
}

ArmVector PlanarArm::moving_part(const dynamics::JointVector& q) const {
  ArmVector a(moving());
  for (int k = 0; k < moving(); ++k) a[k] = q[joint(k)];
  return a;
}

Eigen::Vector2d PlanarArm::to_plane(const Eigen::Vector3d& p) const {
  return plane_ * p;
}

Eigen::Vector3d PlanarArm::from_plane(const Eigen::Vector2d& xz) const {
  return plane_.transpose() * xz + normal_ * normal_offset_;
}

Eigen::Vector2d PlanarArm::tip(const ArmVector& a, dynamics::KinematicsData& data) const {
  return plane_ * dynamics::tip_position(*model_, data, full(a));
}

void PlanarArm::jacobian(const ArmVector& a, dynamics::KinematicsData& data,
                         ArmJacobian& out) const {
  dynamics::TaskJacobian j;
  dynamics::tip_jacobian(*model_, data, full(a), j);
  out.resize(2, moving());
  for (int k = 0; k < moving(); ++k) out.col(k) = plane_ * j.col(joint(k));
}

void PlanarArm::statics(const ArmVector& a, dynamics::KinematicsData& data, Statics& out) const {
  const dynamics::JointVector q = full(a);
  dynamics::JointVector effort;
  dynamics::static_gravity_effort(*model_, data, q, effort);
  const int m = moving();
  out.length_m.resize(m);
  out.arm.resize(m);
  out.force_n.resize(m);
  for (int k = 0; k < m; ++k) {
    const dynamics::Cylinder& c = model_->cylinders[at(joint(k))];
    out.length_m[k] = dynamics::cylinder_length(c, q[joint(k)]);
    out.arm[k] = dynamics::cylinder_arm(c, q[joint(k)]);
    out.force_n[k] = std::abs(out.arm[k]) > 1e-12 ? effort[joint(k)] / out.arm[k] : 0.0;
  }
}

void PlanarArm::restrict_set(const dynamics::JointVelocitySet& s,
                             dynamics::JointVelocitySet& out) const {
  const int m = moving();
  out.qdot_min.resize(m);
  out.qdot_max.resize(m);
  out.flow_positive_m3.resize(m);
  out.flow_negative_m3.resize(m);
  for (int k = 0; k < m; ++k) {
    out.qdot_min[k] = s.qdot_min[joint(k)];
    out.qdot_max[k] = s.qdot_max[joint(k)];
    out.flow_positive_m3[k] = s.flow_positive_m3[joint(k)];
    out.flow_negative_m3[k] = s.flow_negative_m3[joint(k)];
  }
  out.max_flow_m3_s = s.max_flow_m3_s;
}

double PlanarArm::tip_speed_bound(const ArmVector& speed) const {
  double bound = 0.0;
  const int n = model_->dof();
  for (int k = 0; k < moving(); ++k) {
    const int i = joint(k);
    const dynamics::DhJoint& jnt = model_->joints[at(i)];
    const dynamics::Cylinder& c = model_->cylinders[at(i)];
    double arm_min = std::numeric_limits<double>::infinity();
    constexpr int kSamples = 400;
    for (int s = 0; s <= kSamples; ++s) {
      const double q = jnt.q_min + (jnt.q_max - jnt.q_min) * s / kSamples;
      arm_min = std::min(arm_min, std::abs(dynamics::cylinder_arm(c, q)));
    }
    if (!(arm_min > 1e-12)) return std::numeric_limits<double>::infinity();
    double reach = 1.0;  // a prismatic joint moves the tip as fast as itself
    if (jnt.type == JointType::kRevolute) {
      reach = 0.0;
      for (int l = i; l < n; ++l) {
        const dynamics::DhJoint& next = model_->joints[at(l)];
        reach += std::abs(next.a_m) + std::abs(next.d_m) +
                 (next.type == JointType::kPrismatic
                      ? std::max(std::abs(next.q_min), std::abs(next.q_max))
                      : 0.0);
      }
    }
    bound += reach * speed[k] / arm_min;
  }
  return bound;
}

}  // namespace craneassist::planner
