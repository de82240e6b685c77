#include "craneassist/dynamics/flow_polytope.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "craneassist/dynamics/hydraulics.hpp"

namespace craneassist::dynamics {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinArm = 1e-12;  // m/rad or m/m: no torque arm (as the scaling stage treats it)
constexpr double kRoundingRate = 1e-12;  // rad/s or m/s (per unit of a direction): not moving
// Relative tolerances of the vertex enumeration: a flow sum this close to Q_max is at it, a
// flow-set rate this close to 0 or its bound is there (another pattern gives that point).
constexpr double kFlowActive = 1e-12;
constexpr double kInterior = 1e-12;
// A singular value below this share of the largest is zero (the task loses a direction); a
// direction with this share of itself outside the task's range cannot be moved along.
constexpr double kRankTolerance = 1e-9;
constexpr double kRangeTolerance = 1e-9;

std::size_t at(int i) {
  return static_cast<std::size_t>(i);
}

int power(int base, int exponent) {
  int r = 1;
  for (int k = 0; k < exponent; ++k) r *= base;
  return r;
}

}  // namespace

void joint_velocity_set(const CraneModel& model, const JointVector& q, const JointVector& dc_dq,
                        const FlowPolytopeSettings& settings, JointVelocitySet& out) {
  const int n = model.dof();
  out.qdot_min.resize(n);
  out.qdot_max.resize(n);
  out.flow_positive_m3.resize(n);
  out.flow_negative_m3.resize(n);
  out.max_flow_m3_s = flow_budget_m3_s(model, settings.flow_reserve);
  for (int i = 0; i < n; ++i) {
    const Cylinder& cyl = model.cylinders[at(i)];
    const DhJoint& joint = model.joints[at(i)];
    const double r = dc_dq[i];
    if (!(std::abs(r) > kMinArm)) {
      out.qdot_min[i] = out.qdot_max[i] = 0.0;
      out.flow_positive_m3[i] = out.flow_negative_m3[i] = 0.0;
      continue;
    }
    const double rate = cylinder_speed_cap_m_s(cyl, settings.cylinder_speed_reserve) / std::abs(r);
    out.qdot_max[i] = rate;
    out.qdot_min[i] = -rate;
    // A positive joint rate moves the cylinder in the sign of r.
    out.flow_positive_m3[i] = cylinder_flow_m3_s(cyl, r);
    out.flow_negative_m3[i] = cylinder_flow_m3_s(cyl, -r);
    if (settings.joint_ends) {
      if (q[i] >= joint.q_max - settings.end_tolerance) out.qdot_max[i] = 0.0;
      if (q[i] <= joint.q_min + settings.end_tolerance) out.qdot_min[i] = 0.0;
    }
  }
}

double limit_usage(const JointVelocitySet& set, const JointVector& qdot) {
  double usage = 0.0, flow = 0.0;
  for (Eigen::Index i = 0; i < qdot.size(); ++i) {
    const double v = qdot[i];
    // Against a bound of 0 (a joint at its end) a rate below kRoundingRate is rounding, not
    // motion (the scaling stage ignores it the same way).
    if (v > 0.0) {
      if (set.qdot_max[i] > 0.0) {
        usage = std::max(usage, v / set.qdot_max[i]);
      } else if (v > kRoundingRate) {
        usage = kInf;
      }
      flow += set.flow_positive_m3[i] * v;
    } else if (v < 0.0) {
      if (set.qdot_min[i] < 0.0) {
        usage = std::max(usage, v / set.qdot_min[i]);
      } else if (v < -kRoundingRate) {
        usage = kInf;
      }
      flow -= set.flow_negative_m3[i] * v;
    }
  }
  if (flow > 0.0)
    usage = std::max(usage, set.max_flow_m3_s > 0.0 ? flow / set.max_flow_m3_s : kInf);
  return usage;
}

double speed_along(const JointVelocitySet& set, const JointVector& direction) {
  const double usage = limit_usage(set, direction);
  return usage > 0.0 ? 1.0 / usage : kInf;
}

int max_joint_vertices(int dof) {
  // sum_k C(n,k) 2^k (k + 1): k moving joints, each either way, all at bounds or one set by the
  // flow.
  int total = 0, binomial = 1;
  for (int k = 0; k <= dof; ++k) {
    total += binomial * power(2, k) * (k + 1);
    binomial = binomial * (dof - k) / (k + 1);
  }
  return total;
}

int joint_velocity_vertices(const JointVelocitySet& set, Eigen::Ref<Eigen::MatrixXd> out) noexcept {
  const int n = static_cast<int>(set.qdot_min.size());
  const double q_max = set.max_flow_m3_s;
  const bool flow_limited = std::isfinite(q_max);
  const int patterns = power(3, n);
  const int capacity = static_cast<int>(out.cols());
  std::array<int, kMaxJoints> sign{};           // 0 rest, +1, -1
  std::array<double, kMaxJoints> bound{}, w{};  // |bound| and flow weight on the pattern's side
  int count = 0;
  for (int code = 0; code < patterns; ++code) {
    int c = code;
    bool usable = true;
    double flow = 0.0;  // every moving joint at its bound
    for (int i = 0; i < n; ++i) {
      const int digit = c % 3;
      c /= 3;
      sign[at(i)] = digit == 0 ? 0 : (digit == 1 ? 1 : -1);
      if (sign[at(i)] == 0) continue;
      bound[at(i)] = sign[at(i)] > 0 ? set.qdot_max[i] : -set.qdot_min[i];
      w[at(i)] = sign[at(i)] > 0 ? set.flow_positive_m3[i] : set.flow_negative_m3[i];
      // A side the joint cannot move to: the pattern with the joint at rest has that point.
      if (!(bound[at(i)] > 0.0)) usable = false;
      flow += w[at(i)] * bound[at(i)];
    }
    if (!usable) continue;
    // A joint at rest is held there by a bound of 0 on a side or, with the flow at its maximum,
    // by the kink of the flow constraint (it costs flow either way). Unless every resting joint
    // is held, the point lies between two others and is no vertex.
    auto resting_held = [&](bool flow_active) {
      for (int i = 0; i < n; ++i) {
        if (sign[at(i)] != 0) continue;
        const bool box = set.qdot_max[i] == 0.0 || set.qdot_min[i] == 0.0;
        const bool kink = flow_active && set.flow_positive_m3[i] + set.flow_negative_m3[i] > 0.0;
        if (!box && !kink) return false;
      }
      return true;
    };
    auto emit = [&](int free_joint, double free_rate) {
      if (count >= capacity) return;
      for (int i = 0; i < n; ++i) {
        out(i, count) = sign[at(i)] * (i == free_joint ? free_rate : bound[at(i)]);
      }
      ++count;
    };
    // (a) every moving joint at its bound.
    if (!flow_limited || flow <= q_max * (1.0 + kFlowActive)) {
      const bool active = flow_limited && flow >= q_max * (1.0 - kFlowActive);
      if (resting_held(active)) emit(-1, 0.0);
    }
    if (!flow_limited || !resting_held(true)) continue;
    // (b) one moving joint set by the flow, strictly inside its range.
    for (int k = 0; k < n; ++k) {
      if (sign[at(k)] == 0 || !(w[at(k)] > 0.0)) continue;
      const double rest = flow - w[at(k)] * bound[at(k)];
      const double rate = (q_max - rest) / w[at(k)];
      if (rate > kInterior * bound[at(k)] && rate < (1.0 - kInterior) * bound[at(k)]) {
        emit(k, rate);
      }
    }
  }
  return count;
}

std::optional<Eigen::Matrix<double, 2, 3>> planar_task_basis(const CraneModel& model) {
  // Every joint axis is parallel to the base z axis when each DH twist is 0 or pi; prismatic
  // joints would move along that axis, out of the plane.
  if (model.dof() == 0) return std::nullopt;
  for (const DhJoint& joint : model.joints) {
    if (joint.type != JointType::kRevolute) return std::nullopt;
    if (std::abs(std::sin(joint.alpha_rad)) > 1e-9) return std::nullopt;
  }
  const Eigen::Vector3d normal = model.task_from_base.col(2).normalized();
  Eigen::Matrix<double, 2, 3> basis;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(std::abs(normal[axis]) - 1.0) < 1e-12) {  // a coordinate plane: its two axes
      int row = 0;
      for (int k = 0; k < 3; ++k) {
        if (k != axis) basis.row(row++) = Eigen::Vector3d::Unit(k).transpose();
      }
      return basis;
    }
  }
  const Eigen::Vector3d e1 = normal.unitOrthogonal();
  basis.row(0) = e1.transpose();
  basis.row(1) = normal.cross(e1).transpose();
  return basis;
}

FlowPolytope::FlowPolytope(int dof, int task_dim)
    : dof_(std::clamp(dof, 1, kMaxJoints)),
      task_dim_(std::clamp(task_dim, 2, 3)),
      task_(TaskMatrix::Zero(task_dim_, dof_)),
      joint_vertices_(Eigen::MatrixXd::Zero(dof_, max_joint_vertices(dof_))),
      points3_(at(max_joint_vertices(dof_))),
      points2_(at(max_joint_vertices(dof_))),
      hull3_(max_joint_vertices(dof_)),
      hull2_(max_joint_vertices(dof_)),
      svd_(task_dim_, dof_, Eigen::ComputeFullU | Eigen::ComputeFullV),
      // Rows: 2n box sides and 2^n flow sign patterns; columns: s and z = z+ - z- (n - rank).
      lp_(2 * dof_ + power(2, dof_), 1 + 2 * dof_) {
  set_.qdot_min.setZero(dof_);
  set_.qdot_max.setZero(dof_);
  set_.flow_positive_m3.setZero(dof_);
  set_.flow_negative_m3.setZero(dof_);
  lp_p_.setZero(dof_);
  lp_qdot_.setZero(dof_);
  flow_row_.setZero(dof_);
}

void FlowPolytope::update(const JointVelocitySet& set, const TaskMatrix& task) noexcept {
  set_ = set;
  task_ = task;
  point_count_ = joint_velocity_vertices(set_, joint_vertices_);
  for (int k = 0; k < point_count_; ++k) {
    const JointVector qdot = joint_vertices_.col(k).head(dof_);
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    x.head(task_dim_) = task_ * qdot;
    points3_[at(k)] = x;
    points2_[at(k)] = x.head<2>();
  }
}

void FlowPolytope::build_hull() noexcept {
  if (task_dim_ == 3) {
    hull3_.build(std::span<const Eigen::Vector3d>(points3_.data(), at(point_count_)));
  } else {
    hull2_.build(std::span<const Eigen::Vector2d>(points2_.data(), at(point_count_)));
  }
}

int FlowPolytope::dimension() const noexcept {
  return task_dim_ == 3 ? hull3_.dimension() : hull2_.dimension();
}

double FlowPolytope::volume() const noexcept {
  return task_dim_ == 3 ? hull3_.volume() : 0.0;
}

double FlowPolytope::area() const noexcept {
  return task_dim_ == 3 ? hull3_.flat_area() : hull2_.area();
}

std::span<const int> FlowPolytope::hull_vertices() const noexcept {
  return task_dim_ == 3 ? hull3_.vertices() : hull2_.vertices();
}

double FlowPolytope::max_speed(const TaskVector& direction) noexcept {
  lp_qdot_.setZero(dof_);
  lp_status_ = LpStatus::kOptimal;
  const double norm = direction.norm();
  if (!(norm > 0.0) || !std::isfinite(norm) || direction.size() != task_dim_) return 0.0;
  const TaskVector u = direction / norm;

  // Every joint velocity with J qdot = s u: qdot = s p + N z.
  svd_.compute(task_, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const auto& sigma = svd_.singularValues();
  if (!(sigma.size() > 0 && sigma[0] > 0.0)) return 0.0;
  int rank = 0;
  while (rank < sigma.size() && sigma[rank] > kRankTolerance * sigma[0]) ++rank;
  const TaskVector c = svd_.matrixU().transpose() * u;
  double outside = 0.0;  // the part of u outside the task's range
  for (int k = rank; k < task_dim_; ++k) outside += c[k] * c[k];
  if (std::sqrt(outside) > kRangeTolerance) return 0.0;  // not a direction it can move along
  const auto& v = svd_.matrixV();
  lp_p_.setZero(dof_);
  for (int k = 0; k < rank; ++k) lp_p_ += v.col(k) * (c[k] / sigma[k]);
  const int nulls = dof_ - rank;

  // max s over (s, z+, z-) >= 0: qdot within the box, and one flow row per sign pattern.
  const bool flow_limited = std::isfinite(set_.max_flow_m3_s);
  const int flow_rows = flow_limited ? power(2, dof_) : 0;
  lp_.reset(2 * dof_ + flow_rows, 1 + 2 * nulls);
  auto fill_row = [&](int row, const JointVector& coeff, double rhs) {
    lp_.a(row, 0) = coeff.dot(lp_p_);
    for (int j = 0; j < nulls; ++j) {
      const double a = coeff.dot(v.col(rank + j));
      lp_.a(row, 1 + 2 * j) = a;
      lp_.a(row, 2 + 2 * j) = -a;
    }
    lp_.b(row) = std::max(rhs, 0.0);
  };
  for (int i = 0; i < dof_; ++i) {
    flow_row_.setZero(dof_);
    flow_row_[i] = 1.0;
    fill_row(2 * i, flow_row_, set_.qdot_max[i]);
    flow_row_[i] = -1.0;
    fill_row(2 * i + 1, flow_row_, -set_.qdot_min[i]);
  }
  for (int pattern = 0; pattern < flow_rows; ++pattern) {
    for (int i = 0; i < dof_; ++i) {
      flow_row_[i] = (pattern >> i) & 1 ? set_.flow_positive_m3[i] : -set_.flow_negative_m3[i];
    }
    fill_row(2 * dof_ + pattern, flow_row_, set_.max_flow_m3_s);
  }
  lp_.c(0) = 1.0;
  lp_status_ = lp_.solve();
  if (lp_status_ != LpStatus::kOptimal) return lp_status_ == LpStatus::kUnbounded ? kInf : 0.0;
  const double s = lp_.x(0);
  lp_qdot_ = s * lp_p_;
  for (int j = 0; j < nulls; ++j) {
    lp_qdot_ += (lp_.x(1 + 2 * j) - lp_.x(2 + 2 * j)) * v.col(rank + j);
  }
  // Rounding can leave a joint pinned at an end moving a hair into it.
  lp_qdot_ = lp_qdot_.cwiseMax(set_.qdot_min).cwiseMin(set_.qdot_max);
  return s;
}

}  // namespace craneassist::dynamics
