// The flow manipulability polytope (docs/algorithms.md section 9; Oda, Suzumura and Hyon, "Motion
// Planning of MHSB for Redundant Hydraulic Manipulators", section 2.1): the tip velocities the
// machine can deliver at a pose, from its cylinder speed limits and its pump's flow.
//
// Joint velocities. Cylinder i moves at v_i = r_i qdot_i (r_i = dc_i/dq_i, signed; cylinders.hpp)
// and may not exceed its speed, |v_i| <= v_max_i. The pump supplies
//     Q(qdot) = sum_i Aflow_i(sign v_i) |v_i| <= Q_max,
// with Aflow the piston area extending and the rod-side area retracting (A_A - A_B extending for
// a cylinder with a differential spool; model.hpp flow_area_m2): exactly the sum the scaling
// stage's flow bound uses (docs/algorithms.md section 2). In joint rates this is a box cut by one
// constraint that is linear in each orthant:
//     qdot_min_i <= qdot_i <= qdot_max_i,   sum_i w_i(sign qdot_i) |qdot_i| <= Q_max,
//     qdot_max_i = -qdot_min_i = v_max_i / |r_i|,   w_i(+-) = |r_i| Aflow_i(sign(+-r_i)).
// A joint at an end may only move away from it (its bound towards the end is 0), as the
// controller's redundancy resolution keeps it. The set is convex: Q(qdot) is a sum of convex
// functions |.| weighted per side.
//
// Its vertices: in each orthant the set is a box [0, b] cut by a plane with positive normal, so a
// vertex has every moving joint at its bound, except at most one, which the flow constraint
// sets. Enumerating the sign patterns {-, 0, +}^n (3^4 = 81 for four joints) and keeping only
// points where the active constraints span the space gives every vertex once.
//
// Tip velocities. The polytope is the image J(q) P of the joint set: the convex hull of the
// images of its vertices (convex_hull.hpp). Its volume (a 3-D tip task, m^3/s^3) or area (a planar
// arm's 2-D task, m^2/s^2) measures how much motion the pose leaves the operator.
//
// Speed along a direction u, two ways:
//  - speed_along(): along one joint direction f (for the controller: f' = f'(s), the joint rate
//    per unit path speed its redundancy resolution chose for u, J f' = u), the largest s with
//    s f in the set. This is exactly the flow and cylinder-speed prescaling bound of the scaling
//    stage, min(sdot_flow, sdot_cylinder) (scaling/path_constraints.hpp).
//  - FlowPolytope::max_speed(): the largest s with s u in J P, over every joint velocity that
//    gives s u (a redundant arm has a line of them). A small LP: with J = U S V^T, every
//    solution of J qdot = s u is qdot = s p + N z (p = J^+ u, N the null space of J), and the
//    set's constraints are linear in (s, z) (2n box rows, 2^n flow rows: one per sign pattern,
//    as sum_i max(w+_i qdot_i, -w-_i qdot_i) is the largest of the 2^n linear sums). Solved by
//    DenseSimplex (small_lp.hpp). It is never below the first: what the machine could do there
//    with the best joint motion, against what the chosen resolution does.
//
// The live use (Controller, every cycle) needs no allocation: FlowPolytope's storage is sized by
// its constructor; update(), build_hull() and max_speed() allocate nothing and throw nothing.
#pragma once

#include <Eigen/Core>
#include <Eigen/SVD>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "craneassist/dynamics/convex_hull.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/small_lp.hpp"

namespace craneassist::dynamics {

// The tip task of the polytope: 3 x n (the tip Jacobian, crane frame) or 2 x n (a planar arm's
// plane, planar_task_basis()).
using TaskMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, kMaxJoints>;
using TaskVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;

// The admissible joint velocities at one pose (see the header comment).
struct JointVelocitySet {
  JointVector qdot_min, qdot_max;  // rad/s or m/s; qdot_min <= 0 <= qdot_max
  // Pump flow per unit joint rate moving positive and negative, m^3/rad or m^3/m (>= 0).
  JointVector flow_positive_m3, flow_negative_m3;
  double max_flow_m3_s = std::numeric_limits<double>::infinity();
};

struct FlowPolytopeSettings {
  // Shares kept back, as in the scaling stage (control.flow_reserve): the flow bound uses
  // Q_max (1 - flow_reserve), the speed bound v_max (1 - cylinder_speed_reserve). The full
  // scaling keeps the reserve on both (path_speed_limits), the flow-only prescaling on the flow
  // only (flow_prescale).
  double flow_reserve = 0.0;
  double cylinder_speed_reserve = 0.0;
  // A joint within end_tolerance of an end (rad or m) may only move away from it (as the tip
  // path's resolution treats it); false: the hydraulics alone.
  bool joint_ends = true;
  double end_tolerance = 1e-4;
};

// The set of the model at q; dc_dq: the torque arms at q (cylinder_arms). A cylinder with no
// torque arm (|dc/dq| < 1e-12, a dead point of its linkage) cannot drive its joint: its joint's
// rates are 0.
void joint_velocity_set(const CraneModel& model, const JointVector& q, const JointVector& dc_dq,
                        const FlowPolytopeSettings& settings, JointVelocitySet& out);

// The share of the set's limits qdot uses: max(|qdot_i| / bound_i, Q(qdot) / Q_max); 1 on the
// boundary, > 1 outside (+inf where a bound is 0 and qdot_i moves against it by more than
// 1e-12, rounding).
double limit_usage(const JointVelocitySet& set, const JointVector& qdot);

// The largest s >= 0 with s direction in the set (1 / limit_usage; +inf for a zero direction).
double speed_along(const JointVelocitySet& set, const JointVector& direction);

// How many vertices the enumeration can produce for n joints: sum_k C(n,k) 2^k (k + 1).
int max_joint_vertices(int dof);

// The vertices of the set, one per column of `out` (dof rows, at least max_joint_vertices
// columns). Returns their number. No allocation.
int joint_velocity_vertices(const JointVelocitySet& set, Eigen::Ref<Eigen::MatrixXd> out) noexcept;

// For a planar arm (every joint revolute about parallel axes), the two rows that map crane-frame
// vectors to coordinates in its plane (coordinate axes when the plane is a coordinate plane,
// e.g. x and y for the planar 2R test arm); nullopt for a spatial crane.
std::optional<Eigen::Matrix<double, 2, 3>> planar_task_basis(const CraneModel& model);

class FlowPolytope {
 public:
  // Storage for an arm of `dof` joints and a tip task of task_dim (2 or 3) coordinates
  // (allocates).
  FlowPolytope(int dof, int task_dim);

  int dof() const noexcept { return dof_; }
  int task_dim() const noexcept { return task_dim_; }

  // A new pose: the set and the task matrix (task_dim x dof). Enumerates the vertices and maps
  // them to the task; the hull waits for build_hull().
  void update(const JointVelocitySet& set, const TaskMatrix& task) noexcept;
  // The convex hull of the task points: volume, area, hull vertices. Separate from update() so a
  // caller may build it less often.
  void build_hull() noexcept;

  // Vertices of the joint-velocity set and their images (a 2-D task: z = 0).
  int point_count() const noexcept { return point_count_; }
  Eigen::MatrixXd::ConstColXpr joint_vertex(int k) const { return joint_vertices_.col(k); }
  std::span<const Eigen::Vector3d> task_points() const noexcept {
    return {points3_.data(), static_cast<std::size_t>(point_count_)};
  }

  // After build_hull(). Dimension of the hull (task_dim for a full polytope; less at a singular
  // pose or with every joint pinned).
  int dimension() const noexcept;
  // A 3-D task's volume, m^3/s^3 (0 when flat).
  double volume() const noexcept;
  // A 2-D task's area, m^2/s^2; a flat 3-D polytope's area in its plane.
  double area() const noexcept;
  // Indices into task_points() of the hull's vertices.
  std::span<const int> hull_vertices() const noexcept;
  const ConvexHull3& hull3() const noexcept { return hull3_; }
  const ConvexHull2& hull2() const noexcept { return hull2_; }

  // The largest tip speed along u (normalised here; task_dim coordinates) over every admissible
  // joint velocity, m/s: the LP. 0 for a zero u or a u the arm cannot move along at this pose.
  double max_speed(const TaskVector& u) noexcept;
  // The joint velocity that reaches it (s p + N z at the optimum).
  const JointVector& max_speed_joint_velocity() const noexcept { return lp_qdot_; }
  LpStatus lp_status() const noexcept { return lp_status_; }

 private:
  int dof_, task_dim_;
  JointVelocitySet set_;
  TaskMatrix task_;
  Eigen::MatrixXd joint_vertices_;  // dof x max_joint_vertices
  std::vector<Eigen::Vector3d> points3_;
  std::vector<Eigen::Vector2d> points2_;
  int point_count_ = 0;
  ConvexHull3 hull3_;
  ConvexHull2 hull2_;
  // The LP's working data.
  Eigen::JacobiSVD<TaskMatrix> svd_;
  DenseSimplex lp_;
  LpStatus lp_status_ = LpStatus::kOptimal;
  JointVector lp_p_, lp_qdot_, flow_row_;
};

}  // namespace craneassist::dynamics
