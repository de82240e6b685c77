#include "craneassist/scaling/tip_path.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/hydraulics.hpp"
#include "craneassist/scaling/scaling_filter.hpp"

namespace craneassist::scaling {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kAtLimit = 1e-4;         // rad or m: a joint this close to its end is at it
constexpr double kMinSpeed = 1e-3;        // m/s: the smallest intended speed the bounds assume
constexpr double kRestSpeed = 1e-3;       // m/s: below this there is no window
constexpr double kDifferenceStep = 1e-5;  // m of path for f''
// Shares of the path's deceleration and jerk the end damping assumes: the rest is margin for the
// jerk-limited filter, which follows a falling cap a few cycles late.
constexpr double kEndDecelerationShare = 0.8;
constexpr double kEndJerkShare = 0.8;
constexpr double kEndMarginCycles = 4.0;  // of travel at the present speed, kept before an end
// Null-space moves: at most this share of a joint's acceleration, reached in kNullRampTime.
constexpr double kNullAccelShare = 0.5;
constexpr double kNullRampTime = 0.3;     // s
constexpr double kNullOffset = 1e3;       // keeps the filter's target away from zero (its "stop")
constexpr double kHandoverShare = 0.4;    // of the others' accelerations, to take a joint's motion
constexpr double kHandoverMargin = 0.02;  // of a joint's range: hand-overs end this far from it
constexpr double kMinLeverage = 1e-3;     // null-vector component of a joint the null space moves
constexpr double kMaxWeight = 1e6;
constexpr double kNegligibleRate = 1e-9;  // rad or m per metre of path: not moving

}  // namespace

TipPath::TipPath(const dynamics::CraneModel& model, const TipPathConfig& config)
    : model_(model), config_(config) {
  const int n = model.dof();
  joint_accel_max_.setZero(n);
  bounds_.lower.setZero(n);
  bounds_.upper.setZero(n);
  problem_.position.lower.setZero(n);
  problem_.position.upper.setZero(n);
  problem_.hydraulic.lower.setZero(n);
  problem_.hydraulic.upper.setZero(n);
  problem_.handover.lower.setZero(n);
  problem_.handover.upper.setZero(n);
  problem_.avoid_weight.setZero(n);
  problem_.avoid_sign.setZero(n);
  previous_f1_.setZero(n);
  q_shift_.setZero(n);
  f1_plus_.setZero(n);
  f1_minus_.setZero(n);
  arms_.setZero(n);
  force_.setZero(n);
}

void TipPath::reset() {
  has_previous_ = false;
  null_rate_ = 0.0;
}

void TipPath::resolve(const JointVector& q, const Eigen::Vector3d& u, const Shape& shape,
                      JointVector& f1, dynamics::NullSpaceStatus& status) noexcept {
  const int n = model_.dof();
  dynamics::tip_jacobian(model_, kin_, q, jacobian_);
  dynamics::cylinder_arms(model_, q, arms_);
  for (int i = 0; i < n; ++i) {
    joint_accel_max_[i] = model_.cylinders[static_cast<std::size_t>(i)].a_max_m_s2 /
                          std::max(std::abs(arms_[i]), 1e-12);
  }
  const double sigma = shape.intended_speed;

  // Velocity bounds per unit path speed shaped from the position limits: stop within the path's
  // stopping distance, and within the cylinder's deceleration.
  auto towards_end = [&](double distance, int i) {
    const double room = distance - kAtLimit;
    if (!(room > 0.0)) return 0.0;
    const double by_path = shape.stop_length > 0.0 ? room / shape.stop_length : kInf;
    const double by_cylinder = kEndDecelerationShare *
                               std::sqrt(2.0 * kEndDecelerationShare * joint_accel_max_[i] * room) /
                               sigma;
    return std::min(by_path, by_cylinder);
  };
  for (int i = 0; i < n; ++i) {
    const auto& joint = model_.joints[static_cast<std::size_t>(i)];
    bounds_.upper[i] = towards_end(joint.q_max - q[i], i);
    bounds_.lower[i] = -towards_end(q[i] - joint.q_min, i);
  }

  if (n == 4 && dynamics::solution_line(jacobian_, u, line_)) {
    problem_.line = &line_;
    problem_.dc_dq = &arms_;
    problem_.cylinder_force = &force_;  // this update's copy of the forces (update())
    problem_.position = bounds_;
    for (int i = 0; i < n; ++i) {
      const auto& cyl = model_.cylinders[static_cast<std::size_t>(i)];
      const double rate = dynamics::cylinder_speed_cap_m_s(cyl, config_.flow_reserve) /
                          std::max(std::abs(arms_[i]), 1e-12) / sigma;
      problem_.hydraulic.upper[i] = rate;
      problem_.hydraulic.lower[i] = -rate;
    }
    problem_.flow_limit_m2 = dynamics::flow_budget_m3_s(model_, config_.flow_reserve) / sigma;
    // Hand-over bounds: a joint moving towards an end slows down no faster than the others can
    // take its motion over through the null space (n_k / n_i of it each) within a share of their
    // accelerations, ending kHandoverMargin of its range before the end.
    for (int i = 0; i < n; ++i) {
      double rho = kInf;  // joint i's deceleration through the hand-over, rad/s^2 or m/s^2
      for (int k = 0; k < n; ++k) {
        if (k != i && std::abs(line_.n[k]) > 1e-9) {
          rho = std::min(rho, kHandoverShare * joint_accel_max_[k] * std::abs(line_.n[i]) /
                                  std::abs(line_.n[k]));
        }
      }
      const auto& joint = model_.joints[static_cast<std::size_t>(i)];
      const double range = joint.q_max - joint.q_min;
      const double margin = kHandoverMargin * range;
      const double zone = config_.end_zone * range;
      // Only inside the end zone, and only for joints the null space moves at all.
      const bool leverage = std::abs(line_.n[i]) > kMinLeverage;
      auto handover = [&](double distance) {
        if (!leverage || distance >= zone || std::isinf(rho)) return kInf;
        return std::sqrt(2.0 * rho * std::max(distance - margin, 0.0)) / sigma;
      };
      problem_.handover.upper[i] = std::min(bounds_.upper[i], handover(joint.q_max - q[i]));
      problem_.handover.lower[i] = std::max(bounds_.lower[i], -handover(q[i] - joint.q_min));
    }
    // End avoidance inside the end zone.
    for (int i = 0; i < n; ++i) {
      const auto& joint = model_.joints[static_cast<std::size_t>(i)];
      const double up = joint.q_max - q[i], down = q[i] - joint.q_min;
      const double zone = config_.end_zone * (joint.q_max - joint.q_min);
      const double near = std::max(std::min(up, down), 0.0);
      problem_.avoid_sign[i] = up < down ? 1.0 : -1.0;
      double w = 0.0;
      if (config_.end_weight > 0.0 && near < zone) {
        const double r = zone / std::max(near, zone / kMaxWeight) - 1.0;
        w = std::min(config_.end_weight * r * r, kMaxWeight);
      }
      problem_.avoid_weight[i] = w;
    }
    dynamics::resolve_null_space(model_, config_.resolution, problem_, result_);
    status = result_.status;
    // The null coordinate moves towards the optimum jerk-limited: the null-space part of each
    // joint's acceleration within a share of its limit, ramped up and down in kNullRampTime, so
    // that a switch of the optimum (a joint handed over, a cylinder coming to rest) neither steps
    // nor kinks the joint rates. Only the end interval is hard.
    double tau = result_.tau;
    null_rate_next_ = 0.0;
    if (shape.smooth) {
      const double tau0 = line_.n.dot(previous_f1_ - line_.p);
      // At the edge of the workspace along u, no solution keeps every joint on its stop curve:
      // the null coordinate is held (its motion braked) and the end damping stops the path along
      // the present joint motion, instead of chasing solutions that need ever faster joints.
      if (result_.status == dynamics::NullSpaceStatus::kPositionLimit) tau = tau0;
      double rate = kInf, jerk = kInf;
      for (int i = 0; i < n; ++i) {
        const double lever = std::abs(line_.n[i]) * shape.sdot;
        if (lever > 0.0) {
          rate = std::min(rate, kNullAccelShare * joint_accel_max_[i] / lever);
          jerk = std::min(jerk, kNullAccelShare * joint_accel_max_[i] / (kNullRampTime * lever));
        }
      }
      ScalingFilter filter(ScalingFilterConfig{config_.period_s, jerk});
      filter.reset({0.0, kNullOffset + tau0, null_rate_, 0.0});
      ScalingFilterState st;
      filter.update({kNullOffset + tau, -rate, rate}, st);
      tau = std::clamp(st.sdot - kNullOffset, result_.hard_lo, result_.hard_hi);
      null_rate_next_ = tau == st.sdot - kNullOffset ? st.sddot : (tau - tau0) / config_.period_s;
    }
    f1 = line_.p + tau * line_.n;
    target_f1_ = result_.status == dynamics::NullSpaceStatus::kPositionLimit ? f1 : result_.f;
    return;
  }
  // Other structures, and the exact singular pose: the SNS within the same bounds. J f1 = u
  // exactly when the saturated resolution can do the task at all.
  dynamics::sns_velocity_ik(jacobian_, u, bounds_, sns_);
  f1 = sns_.task_scale > 1e-6 ? JointVector(sns_.qdot / sns_.task_scale) : JointVector::Zero(n);
  target_f1_ = f1;
  status = sns_.task_scale < 1.0 - 1e-9 ? dynamics::NullSpaceStatus::kPositionLimit
                                        : dynamics::NullSpaceStatus::kOptimal;
}

void TipPath::update(const JointVector& q, const TipPathInput& in, TipPathOutput& out) noexcept {
  const int n = model_.dof();
  const Eigen::Vector3d u = in.direction;
  // The loads the resolution works with, copied: resolve() points problem_ at force_.
  if (in.forces_known && in.cylinder_force.size() == n) {
    force_ = in.cylinder_force;
  } else {
    force_.setZero(n);  // no loads known: min-ls-power then minimises flow at the margin
  }

  Shape shape;
  shape.intended_speed = std::max({in.intended_speed, in.sdot, kMinSpeed});
  shape.stop_length =
      stop_distance(shape.intended_speed, kEndDecelerationShare * config_.deceleration_max,
                    kEndJerkShare * config_.jerk_max) +
      kEndMarginCycles * shape.intended_speed * config_.period_s;
  // Smoothing needs a previous solution for (nearly) this direction, and motion.
  shape.sdot = in.sdot;
  shape.smooth = has_previous_ && in.sdot > kRestSpeed && u.dot(previous_u_) > 0.9;

  auto& g = out.geometry;
  resolve(q, u, shape, g.f1, out.status);
  const double null_rate = null_rate_next_;
  heading_f1_ = target_f1_;  // where the null-space filter is heading
  g.dc_dq = arms_;
  jacobian_at_q_ = jacobian_;
  for (int i = 0; i < n; ++i) {
    // At an end, and the resolution does not move it away (so it is pinned there).
    const auto& joint = model_.joints[static_cast<std::size_t>(i)];
    at_end_[i] = (q[i] >= joint.q_max - kAtLimit && g.f1[i] >= 0.0) ||
                 (q[i] <= joint.q_min + kAtLimit && g.f1[i] <= 0.0);
  }
  // f'' = d f'/ds = (df'/dq) f', central difference along the path.
  dynamics::NullSpaceStatus ignored;
  q_shift_ = q + kDifferenceStep * g.f1;
  resolve(q_shift_, u, shape, f1_plus_, ignored);
  q_shift_ = q - kDifferenceStep * g.f1;
  resolve(q_shift_, u, shape, f1_minus_, ignored);
  g.f2 = (f1_plus_ - f1_minus_) / (2.0 * kDifferenceStep);
  previous_f1_ = g.f1;
  previous_u_ = u;
  null_rate_ = null_rate;
  has_previous_ = true;
  g.d2c_dq2.resize(n);
  for (int i = 0; i < n; ++i) {
    g.d2c_dq2[i] =
        dynamics::cylinder_arm_slope(model_.cylinders[static_cast<std::size_t>(i)], q[i]);
  }

  // End damping: the backstop at the edge of the workspace. The path decelerates no faster than
  // its deceleration bound and each cylinder's acceleration limit along f' allow.
  const double sdot = in.sdot;
  double path_decel = config_.deceleration_max;
  for (int i = 0; i < n; ++i) {
    const double v = std::abs(g.dc_dq[i] * g.f1[i]);  // cylinder speed per unit path speed
    if (v > kNegligibleRate) {
      path_decel =
          std::min(path_decel, model_.cylinders[static_cast<std::size_t>(i)].a_max_m_s2 / v);
    }
  }
  out.sdot_joint_limit = g.f1.isZero(0.0) ? 0.0 : kInf;
  out.end_distance_m = g.f1.isZero(0.0) ? 0.0 : kInf;
  out.limiting_joint = -1;
  const double stop_decel = kEndDecelerationShare * path_decel;
  const double stop_jerk = kEndJerkShare * config_.jerk_max;
  out.stop_deceleration_m_s2 = stop_decel;
  out.stop_jerk_m_s3 = stop_jerk;
  for (int i = 0; i < n; ++i) {
    const auto& joint = model_.joints[static_cast<std::size_t>(i)];
    // Joint rate per unit path speed towards each end: the present one, or the one the
    // null-space filter heads for when that is faster (it gets there within a stop).
    const double towards_max = std::max({g.f1[i], heading_f1_[i], 0.0});
    const double towards_min = std::min({g.f1[i], heading_f1_[i], 0.0});
    for (const double rate : {towards_max, towards_min}) {
      if (std::abs(rate) < kNegligibleRate) continue;
      const double sign = rate > 0.0 ? 1.0 : -1.0;
      const double distance = rate > 0.0 ? joint.q_max - q[i] : q[i] - joint.q_min;
      // Path length until the joint reaches its end, looking ahead: along the path its rate
      // grows by f'' per metre (near a singular pose, fast), so it covers
      // |f'| x + max(0, sign f'') x^2 / 2 in x metres.
      const double room = distance - kEndMarginCycles * std::abs(rate) * sdot * config_.period_s;
      const double a = 0.5 * std::max(sign * g.f2[i], 0.0), b = std::abs(rate);
      double length = 0.0;
      if (room > 0.0) {
        length = a > 0.0 ? 2.0 * room / (b + std::sqrt(b * b + 4.0 * a * room)) : room / b;
      }
      const double cap = max_speed_to_stop_within(length, stop_decel, stop_jerk);
      out.end_distance_m = std::min(out.end_distance_m, length);
      if (cap < out.sdot_joint_limit) {
        out.sdot_joint_limit = cap;
        out.limiting_joint = i;
      }
    }
  }
  weakest_direction(u, g.dc_dq, out);
}

void TipPath::weakest_direction(const Eigen::Vector3d& u, const JointVector& arms,
                                TipPathOutput& out) noexcept {
  // The tip velocities the cylinders can give at full speed form an ellipsoid J D (D: the joint
  // rate limits); its smallest semi-axis is the slowest direction.
  // Joints at an end count only when u moves them away from it: at the end they cannot help in
  // the other direction, so e.g. the boom stretched straight with the extension at its end is
  // singular for a radial motion.
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < jacobian_at_q_.cols(); ++i) {
    if (at_end_[i]) continue;
    const double rate_max = model_.cylinders[static_cast<std::size_t>(i)].v_max_m_s /
                            std::max(std::abs(arms[i]), 1e-12);
    const Eigen::Vector3d c = jacobian_at_q_.col(i) * rate_max;
    m += c * c.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
  out.weakest_speed_m_s = std::sqrt(std::max(eig.eigenvalues()[0], 0.0));
  const Eigen::Vector3d weak = eig.eigenvectors().col(0);
  out.near_singular =
      out.weakest_speed_m_s < config_.singularity_speed && std::abs(weak.dot(u)) > 0.2;
}

}  // namespace craneassist::scaling
