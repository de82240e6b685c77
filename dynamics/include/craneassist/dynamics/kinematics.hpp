// Forward kinematics, tip Jacobian and its time derivative for a DH chain.
#pragma once

#include <Eigen/Geometry>
#include <array>

#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

// Per-evaluation buffers (Pinocchio's Data): frame poses in the base frame.
struct KinematicsData {
  // frames[0] is the base; frames[i] is DH frame i after joint i.
  std::array<Eigen::Isometry3d, kMaxJoints + 1> frames;
  // Angular velocity of frame i in the base frame (filled by tip_jacobian_dot).
  std::array<Eigen::Vector3d, kMaxJoints + 1> omega;
  std::array<Eigen::Vector3d, kMaxJoints + 1> origin_velocity;
};

// DH transform of joint i at coordinate q.
Eigen::Isometry3d dh_transform(const DhJoint& joint, double q);

// Fills data.frames for q. Cost O(n).
void forward_kinematics(const CraneModel& model, KinematicsData& data, const JointVector& q);

// Tip position in the crane (task) frame. Calls forward_kinematics.
Eigen::Vector3d tip_position(const CraneModel& model, KinematicsData& data, const JointVector& q);

// Tip linear-velocity Jacobian (3 x n) in the crane frame. Calls forward_kinematics.
void tip_jacobian(const CraneModel& model, KinematicsData& data, const JointVector& q,
                  TaskJacobian& jacobian);

// Time derivative of the tip Jacobian at (q, qdot), exact (no finite differences).
void tip_jacobian_dot(const CraneModel& model, KinematicsData& data, const JointVector& q,
                      const JointVector& qdot, TaskJacobian& jacobian_dot);

}  // namespace craneassist::dynamics
