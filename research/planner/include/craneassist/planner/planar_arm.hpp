// The arm the point-to-point planner moves (paper 001 sections 2-3; docs/mhsb.md): the joints of a
// planar arm in its vertical plane, tip coordinates (X, Z) in that plane (X horizontal, outwards;
// Z up). Two kinds of crane qualify:
//  - a planar arm (every joint revolute about parallel horizontal axes, planar_task_basis()):
//    all joints move; the paper's three-link arm, whose (X, Z) are the crane's (x, y);
//  - a slewing crane whose first joint turns about the vertical and whose other joints move in the
//    vertical plane through it (the K70M: lift, tilt, extension): the slew is held where it is.
// The arm's quasi-static terms at a posture: tip, 2 x m Jacobian, cylinder lengths, torque arms
// and the cylinder forces that hold the load (static_gravity.hpp; F = g / (dc/dq)).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "craneassist/dynamics/flow_polytope.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/model.hpp"

namespace craneassist::planner {

using ArmVector = dynamics::JointVector;  // the moving joints' coordinates (m of them)
using ArmJacobian = Eigen::Matrix<double, 2, Eigen::Dynamic, 0, 2, dynamics::kMaxJoints>;

class PlanarArm {
 public:
  // q_hold: a full posture of the crane; the joints the planner does not move (the slew) keep its
  // values, and it picks the plane. Throws std::invalid_argument for a crane of neither kind.
  PlanarArm(const dynamics::CraneModel& model, const dynamics::JointVector& q_hold);

  const dynamics::CraneModel& model() const { return *model_; }
  int moving() const { return static_cast<int>(active_.size()); }  // m
  // The crane's joint index of moving joint k.
  int joint(int k) const { return active_[static_cast<std::size_t>(k)]; }
  const dynamics::JointVector& q_hold() const { return q_hold_; }
  // Rows: the X and Z axes in the crane frame.
  const Eigen::Matrix<double, 2, 3>& plane() const { return plane_; }
  double lower(int k) const;  // joint range of moving joint k
  double upper(int k) const;

  // The full posture for moving-joint coordinates a, and back.
  dynamics::JointVector full(const ArmVector& a) const;
  ArmVector moving_part(const dynamics::JointVector& q) const;
  // A crane-frame point's plane coordinates (X, Z), and back (in the plane).
  Eigen::Vector2d to_plane(const Eigen::Vector3d& p) const;
  Eigen::Vector3d from_plane(const Eigen::Vector2d& xz) const;

  // Tip (X, Z) and the 2 x m Jacobian at a.
  Eigen::Vector2d tip(const ArmVector& a, dynamics::KinematicsData& data) const;
  void jacobian(const ArmVector& a, dynamics::KinematicsData& data, ArmJacobian& out) const;

  // Quasi-static terms of the moving joints at a: cylinder lengths (m), torque arms dc/dq and the
  // cylinder forces that hold the crane and its payload still (N, positive: the load pushes the
  // rod in). No allocation.
  struct Statics {
    ArmVector length_m, arm, force_n;
  };
  void statics(const ArmVector& a, dynamics::KinematicsData& data, Statics& out) const;

  // The admissible joint velocities of the moving joints (flow_polytope.hpp), from the full
  // model's set at the posture with the held joints left out.
  void restrict_set(const dynamics::JointVelocitySet& full_set,
                    dynamics::JointVelocitySet& out) const;

  // An upper bound of the tip speed (m/s) when every cylinder k moves at most at speed_m_s[k]:
  // sum_k R_k v_k / |dc/dq|_min,k, with R_k the reach beyond joint k (sum of the DH lengths) and
  // |dc/dq|_min over its range (sampled); the planner's admissible heuristic divides by it.
  double tip_speed_bound(const ArmVector& cylinder_speed_m_s) const;

 private:
  const dynamics::CraneModel* model_;
  std::vector<int> active_;
  dynamics::JointVector q_hold_;
  Eigen::Matrix<double, 2, 3> plane_;
  Eigen::Vector3d normal_;
  double normal_offset_ = 0.0;
};

}  // namespace craneassist::planner
