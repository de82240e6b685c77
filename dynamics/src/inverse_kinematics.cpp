#include "craneassist/dynamics/inverse_kinematics.hpp"

#include <Eigen/LU>
#include <cmath>

namespace craneassist::dynamics {
namespace {

bool near(double a, double b) {
  return std::abs(a - b) < 1e-9;
}

}  // namespace

const char* to_string(IkStatus status) {
  switch (status) {
    case IkStatus::kOk:
      return "ok";
    case IkStatus::kUnreachable:
      return "unreachable";
    case IkStatus::kOutsideJointLimits:
      return "outside joint limits";
    case IkStatus::kSingular:
      return "singular";
  }
  return "?";
}

bool is_loader_structure(const CraneModel& m) {
  if (m.dof() != 4) return false;
  const auto& j = m.joints;
  return j[0].type == JointType::kRevolute && near(j[0].alpha_rad, M_PI_2) &&
         near(j[0].theta_rad, 0.0) && j[1].type == JointType::kRevolute &&
         near(j[1].alpha_rad, 0.0) && near(j[1].d_m, 0.0) && near(j[1].theta_rad, 0.0) &&
         j[2].type == JointType::kRevolute && near(j[2].alpha_rad, M_PI_2) && near(j[2].d_m, 0.0) &&
         near(j[2].theta_rad, M_PI_2) && j[3].type == JointType::kPrismatic &&
         near(j[3].a_m, 0.0) && near(j[3].alpha_rad, -M_PI_2) && near(j[3].theta_rad, 0.0) &&
         m.task_from_base.isApprox((Eigen::Matrix3d() << 1, 0, 0, 0, 0, 1, 0, 1, 0).finished());
}

IkStatus solve_given_extension(const CraneModel& m, const Eigen::Vector3d& tip, double q4,
                               JointVector& q) {
  const double ox = m.joints[0].a_m, oy = m.joints[0].d_m;
  const double l1 = m.joints[1].a_m, l2 = m.joints[2].a_m;
  const double lt = m.joints[3].d_m + q4;  // L3 + q4
  q.resize(4);
  q[3] = q4;
  // Slew from the bearing (paper 000 eq. 33); the boom points away from the slew axis.
  const double rho = std::hypot(tip.x(), tip.z());
  q[0] = std::atan2(tip.z(), tip.x());
  // Vertical plane: lift joint at (ox, oy); second link of length ell at angle psi = q2+q3+delta.
  const double r = rho - ox, h = tip.y() - oy;
  const double ell = std::hypot(l2, lt);
  const double delta = std::atan2(l2, lt);
  const double cos_e = (r * r + h * h - l1 * l1 - ell * ell) / (2.0 * l1 * ell);
  if (std::abs(cos_e) > 1.0) return IkStatus::kUnreachable;
  const double e = -std::acos(cos_e);  // folded-down tilt
  q[1] = std::atan2(h, r) - std::atan2(ell * std::sin(e), l1 + ell * std::cos(e));
  q[2] = e - delta;
  for (int i = 0; i < 4; ++i) {
    if (q[i] < m.joints[i].q_min || q[i] > m.joints[i].q_max) return IkStatus::kOutsideJointLimits;
  }
  return IkStatus::kOk;
}

IkStatus resolve_rates_given_extension(const TaskJacobian& jacobian, const Eigen::Vector3d& v_tip,
                                       double q4dot, JointVector& qdot) {
  const Eigen::Matrix3d j123 = jacobian.leftCols<3>();
  const Eigen::PartialPivLU<Eigen::Matrix3d> lu(j123);
  if (std::abs(lu.determinant()) < 1e-9) return IkStatus::kSingular;
  qdot.resize(4);
  qdot.head<3>() = lu.solve(v_tip - jacobian.col(3) * q4dot);
  qdot[3] = q4dot;
  return IkStatus::kOk;
}

}  // namespace craneassist::dynamics
