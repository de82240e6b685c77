#include "craneassist/dynamics/redundancy.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace craneassist::dynamics {
namespace {

using WeightedJacobian = TaskJacobian;

// Pseudo-inverse of a 3 x n Jacobian with some columns zeroed: J^T (J J^T)^-1, damped near
// singularity. Returns false when fewer than 3 independent columns remain.
bool pseudo_inverse(const WeightedJacobian& j,
                    Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxJoints, 3>& pinv) {
  const Eigen::Matrix3d jjt = j * j.transpose();
  const double scale = std::max(jjt.trace(), 1e-12);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(jjt);
  const double min_eig = eig.eigenvalues().minCoeff();
  if (min_eig < 1e-10 * scale) return false;
  // Light damping only close to singular, so the exact solution is kept elsewhere.
  const double damping = min_eig < 1e-4 * scale ? 1e-4 * scale - min_eig : 0.0;
  const Eigen::Matrix3d inv = (jjt + damping * Eigen::Matrix3d::Identity()).inverse();
  pinv = j.transpose() * inv;
  return true;
}

}  // namespace

void joint_rate_bounds(const CraneModel& model, const JointVector& q, const JointVector& qdot_max,
                       const JointVector& qddot_max, double period_s, JointRateBounds& out) {
  const int n = model.dof();
  out.lower.resize(n);
  out.upper.resize(n);
  for (int i = 0; i < n; ++i) {
    const auto& joint = model.joints[static_cast<std::size_t>(i)];
    const double to_max = std::max(joint.q_max - q[i], 0.0);
    const double to_min = std::max(q[i] - joint.q_min, 0.0);
    out.upper[i] =
        std::min({qdot_max[i], to_max / period_s, std::sqrt(2.0 * qddot_max[i] * to_max)});
    out.lower[i] =
        -std::min({qdot_max[i], to_min / period_s, std::sqrt(2.0 * qddot_max[i] * to_min)});
  }
}

void sns_velocity_ik(const TaskJacobian& jacobian, const Eigen::Vector3d& v_tip,
                     const JointRateBounds& bounds, SnsResult& out) {
  const auto n = jacobian.cols();
  JointVector w = JointVector::Ones(n);          // 1: joint free, 0: saturated
  JointVector qdot_null = JointVector::Zero(n);  // saturated joints' rates
  Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxJoints, 3> pinv(n, 3);
  WeightedJacobian jw = jacobian;

  double best_scale = -1.0;
  JointVector best_w = w, best_null = qdot_null;
  out.qdot.setZero(n);
  out.task_scale = 0.0;
  out.saturated_joints = 0;

  for (int iteration = 0; iteration <= n; ++iteration) {
    for (Eigen::Index i = 0; i < n; ++i) jw.col(i) = jacobian.col(i) * w[i];
    const bool full_rank = pseudo_inverse(jw, pinv);
    if (full_rank) {
      const JointVector a = pinv * v_tip;
      const JointVector b = qdot_null - pinv * (jacobian * qdot_null);
      const JointVector qdot = a + b;
      bool inside = true;
      for (Eigen::Index i = 0; i < n; ++i) {
        inside = inside && qdot[i] >= bounds.lower[i] - 1e-12 && qdot[i] <= bounds.upper[i] + 1e-12;
      }
      if (inside) {
        out.qdot = qdot;
        out.task_scale = 1.0;
        out.saturated_joints = static_cast<int>((w.array() == 0.0).count());
        return;
      }
      // Largest task scale this saturation set allows, and the joint that limits it.
      double s_max = std::numeric_limits<double>::infinity();
      double s_min = -std::numeric_limits<double>::infinity();
      Eigen::Index critical = -1;
      for (Eigen::Index i = 0; i < n; ++i) {
        if (w[i] == 0.0) continue;
        double lo = -std::numeric_limits<double>::infinity();
        double hi = std::numeric_limits<double>::infinity();
        if (std::abs(a[i]) > 1e-12) {
          lo = (bounds.lower[i] - b[i]) / a[i];
          hi = (bounds.upper[i] - b[i]) / a[i];
          if (lo > hi) std::swap(lo, hi);
        } else if (b[i] < bounds.lower[i] || b[i] > bounds.upper[i]) {
          hi = -std::numeric_limits<double>::infinity();  // infeasible whatever the scale
        }
        if (hi < s_max) {
          s_max = hi;
          critical = i;
        }
        s_min = std::max(s_min, lo);
      }
      const double scale = (s_min <= s_max) ? std::clamp(s_max, 0.0, 1.0) : 0.0;
      if (scale > best_scale) {
        best_scale = scale;
        best_w = w;
        best_null = qdot_null;
      }
      if (critical < 0) break;
      // Saturate the critical joint at the bound it crosses as the task scale grows.
      const bool towards_upper =
          std::abs(a[critical]) > 1e-12 ? a[critical] > 0.0 : b[critical] > bounds.upper[critical];
      w[critical] = 0.0;
      qdot_null[critical] = towards_upper ? bounds.upper[critical] : bounds.lower[critical];
    } else {
      break;
    }
  }
  // No saturation set meets the full task: use the best scaled one.
  if (best_scale < 0.0) return;  // degenerate Jacobian: stay still
  for (Eigen::Index i = 0; i < n; ++i) jw.col(i) = jacobian.col(i) * best_w[i];
  if (!pseudo_inverse(jw, pinv)) return;
  out.task_scale = best_scale;
  out.qdot = best_null + pinv * (best_scale * v_tip - jacobian * best_null);
  for (Eigen::Index i = 0; i < n; ++i) {
    out.qdot[i] = std::clamp(out.qdot[i], bounds.lower[i], bounds.upper[i]);
  }
  out.saturated_joints = static_cast<int>((best_w.array() == 0.0).count());
}

}  // namespace craneassist::dynamics
