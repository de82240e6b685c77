#include "craneassist/dynamics/kinematics.hpp"

#include <cmath>

namespace craneassist::dynamics {

Eigen::Isometry3d dh_transform(const DhJoint& joint, double q) {
  const double theta = joint.type == JointType::kRevolute ? joint.theta_rad + q : joint.theta_rad;
  const double d = joint.type == JointType::kPrismatic ? joint.d_m + q : joint.d_m;
  const double ct = std::cos(theta), st = std::sin(theta);
  const double ca = std::cos(joint.alpha_rad), sa = std::sin(joint.alpha_rad);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() << ct, -st * ca, st * sa,  //
      st, ct * ca, -ct * sa,            //
      0.0, sa, ca;
  t.translation() << joint.a_m * ct, joint.a_m * st, d;
  return t;
}

void forward_kinematics(const CraneModel& model, KinematicsData& data, const JointVector& q) {
  data.frames[0] = Eigen::Isometry3d::Identity();
  for (int i = 0; i < model.dof(); ++i) {
    data.frames[i + 1] = data.frames[i] * dh_transform(model.joints[i], q[i]);
  }
}

Eigen::Vector3d tip_position(const CraneModel& model, KinematicsData& data, const JointVector& q) {
  forward_kinematics(model, data, q);
  return model.task_from_base * data.frames[model.dof()].translation();
}

void tip_jacobian(const CraneModel& model, KinematicsData& data, const JointVector& q,
                  TaskJacobian& jacobian) {
  forward_kinematics(model, data, q);
  const int n = model.dof();
  const Eigen::Vector3d p = data.frames[n].translation();
  jacobian.resize(3, n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d z = data.frames[i].linear().col(2);
    const Eigen::Vector3d col = model.joints[i].type == JointType::kRevolute
                                    ? Eigen::Vector3d(z.cross(p - data.frames[i].translation()))
                                    : z;
    jacobian.col(i) = model.task_from_base * col;
  }
}

void tip_jacobian_dot(const CraneModel& model, KinematicsData& data, const JointVector& q,
                      const JointVector& qdot, TaskJacobian& jacobian_dot) {
  forward_kinematics(model, data, q);
  const int n = model.dof();
  // Angular velocity of each frame and linear velocity of each frame origin, base to tip.
  data.omega[0].setZero();
  data.origin_velocity[0].setZero();
  for (int k = 1; k <= n; ++k) {
    const Eigen::Vector3d z = data.frames[k - 1].linear().col(2);
    const bool revolute = model.joints[k - 1].type == JointType::kRevolute;
    data.omega[k] =
        data.omega[k - 1] + (revolute ? Eigen::Vector3d(z * qdot[k - 1]) : Eigen::Vector3d::Zero());
    data.origin_velocity[k] =
        data.origin_velocity[k - 1] +
        data.omega[k].cross(data.frames[k].translation() - data.frames[k - 1].translation()) +
        (revolute ? Eigen::Vector3d::Zero() : Eigen::Vector3d(z * qdot[k - 1]));
  }
  const Eigen::Vector3d p = data.frames[n].translation();
  const Eigen::Vector3d p_dot = data.origin_velocity[n];
  jacobian_dot.resize(3, n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d z = data.frames[i].linear().col(2);
    const Eigen::Vector3d z_dot = data.omega[i].cross(z);
    Eigen::Vector3d col;
    if (model.joints[i].type == JointType::kRevolute) {
      col =
          z_dot.cross(p - data.frames[i].translation()) + z.cross(p_dot - data.origin_velocity[i]);
    } else {
      col = z_dot;
    }
    jacobian_dot.col(i) = model.task_from_base * col;
  }
}

}  // namespace craneassist::dynamics
