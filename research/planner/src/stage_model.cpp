#include "craneassist/planner/stage_model.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/inverse_kinematics.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"

namespace craneassist::planner {
namespace {

constexpr double kUnreachablePenaltyFactor = 100.0;

// The planner is offline: a failed dynamics step (ODE out of memory) is an error, not a stop.
void path_terms_or_throw(dynamics::RigidBodyTerms& terms, const JointVector& q,
                         const JointVector& f1, const JointVector& f2, double sdot,
                         dynamics::PathTerms& out) {
  if (!terms.path_terms(q, f1, f2, sdot, out)) {
    throw std::runtime_error("planner: the ODE dynamics step failed (out of memory)");
  }
}

}  // namespace

const char* to_string(PlanCost cost) {
  switch (cost) {
    case PlanCost::kLoadSensing:
      return "ls";
    case PlanCost::kConstantPressure:
      return "cp";
    case PlanCost::kActuatorEnergy:
      return "actuator-energy";
    case PlanCost::kExtension:
      return "extension";
  }
  return "?";
}

StageModel::StageModel(const dynamics::CraneModel& model, TipSamples samples,
                       const StageModelOptions& options)
    : model_(model), samples_(std::move(samples)), options_(options) {
  if (!dynamics::is_loader_structure(model_)) {
    throw std::invalid_argument("the planner needs a loader crane (slew, lift, tilt, extension)");
  }
  const auto& cyl = model_.cylinders[3];
  if (cyl.linkage != dynamics::LinkageType::kConstantArm || !(std::abs(cyl.arm_m) > 0.0)) {
    throw std::invalid_argument("the planner needs a constant-arm extension cylinder");
  }
  if (samples_.p_m.size() < 2 || samples_.v_m_s.size() != samples_.p_m.size() ||
      samples_.a_m_s2.size() != samples_.p_m.size() || !(samples_.dt_s > 0.0)) {
    throw std::invalid_argument("the tip path needs at least two samples and a positive step");
  }
  c0_ = cyl.c0_m;
  arm4_ = cyl.arm_m;
  const double c_a = c_of(model_.joints[3].q_min), c_b = c_of(model_.joints[3].q_max);
  c_min_ = std::min(c_a, c_b);
  c_max_ = std::max(c_a, c_b);
  v_max_ = cyl.v_max_m_s;
  a_max_ = cyl.a_max_m_s2;
  const double dt = samples_.dt_s;
  if (options_.cost == PlanCost::kExtension) {
    scale_ = v_max_ * v_max_ * dt;
  } else {
    scale_ = model_.pump.max_pressure_pa * model_.pump.max_flow_m3_s * dt;
  }
  penalty_ = options_.penalty_factor * scale_;
  for (std::size_t i = 0; i < 4; ++i) inv_a_max_[i] = 1.0 / model_.cylinders[i].a_max_m_s2;
}

void StageModel::position_terms(int k, double c, dynamics::RigidBodyTerms& terms,
                                PositionTerms& out) const {
  const int n = 4;
  const auto ku = static_cast<std::size_t>(k);
  out.reachable = false;
  out.violation = 0.0;
  const double q4 = q4_of(c);
  const auto status = dynamics::solve_given_extension(model_, samples_.p_m[ku], q4, out.q);
  if (status == dynamics::IkStatus::kUnreachable) return;
  for (int i = 0; i < n; ++i) {
    const auto& joint = model_.joints[static_cast<std::size_t>(i)];
    const double range = joint.q_max - joint.q_min;
    out.violation += std::max({joint.q_min - out.q[i], out.q[i] - joint.q_max, 0.0}) / range;
  }

  dynamics::KinematicsData kin;
  dynamics::TaskJacobian jac;
  dynamics::tip_jacobian(model_, kin, out.q, jac);
  const Eigen::Matrix3d j123 = jac.leftCols<3>();
  const Eigen::PartialPivLU<Eigen::Matrix3d> lu(j123);
  if (!(std::abs(lu.determinant()) > 1e-9)) return;
  out.reachable = true;

  out.base.setZero(n);
  out.slope.setZero(n);
  out.base.head<3>() = lu.solve(samples_.v_m_s[ku]);
  out.slope.head<3>() = -lu.solve(Eigen::Vector3d(jac.col(3)));
  out.slope[3] = 1.0;

  // w(t) = [J123^-1 (a - Jdot(q, qdot(t)) qdot(t)); 0] is quadratic in t: three samples.
  const double t_ref = std::max(v_max_ / std::abs(arm4_), 1e-3);
  const std::array<double, 3> ts{-t_ref, 0.0, t_ref};
  std::array<JointVector, 3> w, tau;
  dynamics::TaskJacobian jdot;
  dynamics::PathTerms pt;
  for (std::size_t s = 0; s < 3; ++s) {
    const JointVector qdot = out.base + out.slope * ts[s];
    dynamics::tip_jacobian_dot(model_, kin, out.q, qdot, jdot);
    w[s].setZero(n);
    w[s].head<3>() = lu.solve(samples_.a_m_s2[ku] - jdot * qdot);
    // tau(t, 0) = H w(t) + C(q, qdot(t)) qdot(t) + g: path terms with f' = qdot, f'' = w, sdot = 1.
    path_terms_or_throw(terms, out.q, qdot, w[s], 1.0, pt);
    tau[s] = pt.b;
  }
  const auto fit = [&](const std::array<JointVector, 3>& y, JointVector& c0, JointVector& c1,
                       JointVector& c2) {
    c0 = y[1];
    c1 = (y[2] - y[0]) / (2.0 * t_ref);
    c2 = (y[2] + y[0] - 2.0 * y[1]) / (2.0 * t_ref * t_ref);
  };
  fit(w, out.w0, out.w1, out.w2);
  fit(tau, out.tau0, out.tau1, out.tau2);
  // m = H slope (the effort per unit extension acceleration).
  path_terms_or_throw(terms, out.q, out.slope, JointVector::Zero(n), 0.0, pt);
  out.m = pt.m;

  out.arm.resize(n);
  out.arm_slope.resize(n);
  for (int i = 0; i < n; ++i) {
    const auto& cyl = model_.cylinders[static_cast<std::size_t>(i)];
    out.arm[i] = dynamics::cylinder_arm(cyl, out.q[i]);
    out.arm_slope[i] = dynamics::cylinder_arm_slope(cyl, out.q[i]);
  }
}

void StageModel::velocity_terms(const PositionTerms& pos, double v, VelocityTerms& out) const {
  const int n = 4;
  const double dt = samples_.dt_s;
  out.t = v / arm4_;
  out.moving = 0;
  out.flow_m3_s = 0.0;
  out.base_cost = 0.0;
  out.penalty = 0.0;
  if (!pos.reachable) {
    out.qdot.setZero(n);
    out.v.setZero(n);
    out.acc0.setZero(n);
    out.acc1.setZero(n);
    out.force0.setZero(n);
    out.force1.setZero(n);
    out.inv_area.setZero(n);
    out.penalty = kUnreachablePenaltyFactor * penalty_;
    return;
  }
  const double t = out.t;
  out.qdot = pos.base + pos.slope * t;
  const JointVector w = pos.w0 + pos.w1 * t + pos.w2 * (t * t);
  const JointVector tau = pos.tau0 + pos.tau1 * t + pos.tau2 * (t * t);
  out.v.resize(n);
  out.acc0.resize(n);
  out.acc1.resize(n);
  out.force0.resize(n);
  out.force1.resize(n);
  out.inv_area.resize(n);
  double excess = pos.violation;
  for (int i = 0; i < n; ++i) {
    const auto& cyl = model_.cylinders[static_cast<std::size_t>(i)];
    const double vi = pos.arm[i] * out.qdot[i];
    out.v[i] = vi;
    // Cylinder acceleration r qddot + r' qdot^2, per unit of the control a = arm4 q4ddot.
    out.acc0[i] = pos.arm[i] * w[i] + pos.arm_slope[i] * out.qdot[i] * out.qdot[i];
    out.acc1[i] = pos.arm[i] * pos.slope[i] / arm4_;
    // Cylinder force by virtual work: F = tau / (dc/dq).
    out.force0[i] = tau[i] / pos.arm[i];
    out.force1[i] = pos.m[i] / (pos.arm[i] * arm4_);
    const double area = dynamics::flow_area_m2(cyl, vi);
    out.inv_area[i] = std::copysign(1.0, vi) / area;
    if (std::abs(vi) > options_.at_rest_speed_m_s) out.moving |= 1u << i;
    out.flow_m3_s += area * std::abs(vi);
    excess += std::max(std::abs(vi) / cyl.v_max_m_s - 1.0, 0.0);
  }
  if (excess > 0.0) out.penalty = penalty_ * (1.0 + excess);
  switch (options_.cost) {
    case PlanCost::kConstantPressure:
      out.base_cost = options_.cp_supply_pressure_pa * out.flow_m3_s * dt;
      break;
    case PlanCost::kExtension:
      out.base_cost = v * v * dt;
      break;
    default:
      break;
  }
}

StageCost StageModel::cost(const VelocityTerms& vel, double a) const {
  StageCost out;
  out.penalty = vel.penalty;
  if (vel.penalty >= kUnreachablePenaltyFactor * penalty_) return out;
  const double dt = samples_.dt_s;
  double excess = 0.0, p_max = 0.0, work = 0.0;
  for (int i = 0; i < 4; ++i) {
    const double acc = vel.acc0[i] + vel.acc1[i] * a;
    excess += std::max(std::abs(acc) * inv_a_max_[static_cast<std::size_t>(i)] - 1.0, 0.0);
    if ((vel.moving >> i) & 1u) {
      const double force = vel.force0[i] + vel.force1[i] * a;
      p_max = std::max(p_max, force * vel.inv_area[i]);  // negative: over-running, no pressure
      work += std::max(force * vel.v[i], 0.0);
    }
  }
  excess += std::max(p_max / model_.pump.max_pressure_pa - 1.0, 0.0);
  if (excess > 0.0) out.penalty += penalty_ * (1.0 + excess);
  switch (options_.cost) {
    case PlanCost::kLoadSensing:
      out.cost = vel.moving != 0 ? (p_max + model_.pump.ls_margin_pa) * vel.flow_m3_s * dt : 0.0;
      break;
    case PlanCost::kActuatorEnergy:
      out.cost = work * dt;
      break;
    case PlanCost::kConstantPressure:
    case PlanCost::kExtension:
      out.cost = vel.base_cost;
      break;
  }
  return out;
}

void StageModel::total_costs(const VelocityTerms& vel, double a0, double da, int count,
                             double* totals) const {
  for (int l = 0; l < count; ++l) totals[l] = cost(vel, a0 + da * l).total();
}

void StageModel::joint_accelerations(const PositionTerms& pos, const VelocityTerms& vel, double a,
                                     JointVector& qddot) const {
  const double t = vel.t;
  if (!pos.reachable) {
    qddot.setZero(4);
    return;
  }
  qddot = pos.w0 + pos.w1 * t + pos.w2 * (t * t) + pos.slope * (a / arm4_);
}

StageCost StageModel::evaluate(int k, double c, double v, double a,
                               dynamics::RigidBodyTerms& terms) const {
  PositionTerms pos;
  VelocityTerms vel;
  position_terms(k, c, terms, pos);
  velocity_terms(pos, v, vel);
  return cost(vel, a);
}

}  // namespace craneassist::planner
