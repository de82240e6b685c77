#include "craneassist/app/controller.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "craneassist/dynamics/cylinders.hpp"

namespace craneassist::app {

Controller::Controller(const config::CraneConfig& config, const ControllerOptions& options)
    : model_(config.model),
      options_(options),
      period_s_(1.0 / config.control.rate_hz),
      flow_reserve_(config.control.flow_reserve),
      valves_(config.model, config.control.position_gain_1_s) {
  const int n = model_.dof();
  q_ref_ = config.simulation.q_initial;
  dc_dq_.setZero(n);
  qddot_max_.setZero(n);
  c_ref_.setZero(n);
  c_meas_.setZero(n);
  valve_in_.velocity_ref_m_s.setZero(n);
  valve_in_.position_error_m.setZero(n);
  const double valve_lag_s = model_.valves.delay_s + model_.valves.time_constant_s;
  c_ref_history_.assign(static_cast<std::size_t>(std::lround(valve_lag_s / period_s_)) + 1,
                        JointVector::Zero(n));
}

void Controller::reset(const valves::MachineState& state) {
  q_ref_ = state.q;
  dynamics::cylinder_lengths(model_, q_ref_, c_ref_);
  for (auto& c : c_ref_history_) c = c_ref_;
  history_head_ = 0;
}

void Controller::stop(ControllerOutput& out) {
  const int n = model_.dof();
  out.valves.spool.setZero(n);
  out.qdot_ref.setZero(n);
  out.q_ref = q_ref_;
  out.ref_tip_velocity_m_s.setZero();
  out.scale = 0.0;
  out.flow_demand_m3_s = 0.0;
  out.limit = scaling::ActiveLimit::kStaleInput;
}

ControllerStatus Controller::update(const valves::MachineState& state, const Eigen::Vector3d& v_cmd,
                                    ControllerOutput& out) {
  const int n = model_.dof();
  if (!state.valid || state.q.size() != n || !state.q.allFinite() || !v_cmd.allFinite()) {
    stop(out);
    return ControllerStatus::kStopped;
  }
  // The reference generator runs on its own state q_ref, so the reference tip path is exactly
  // the commanded line; the valves' P term makes the machine follow it (a lagging machine does
  // not bend the reference).
  dynamics::cylinder_arms(model_, q_ref_, dc_dq_);
  for (int i = 0; i < n; ++i) {
    const auto& cyl = model_.cylinders[static_cast<std::size_t>(i)];
    qddot_max_[i] = cyl.a_max_m_s2 / std::abs(dc_dq_[i]);
  }

  // Redundancy resolution. Its bounds only keep the joints off their ends (end damping); speed
  // limits are the prescaling's job, applied uniformly.
  dynamics::tip_jacobian(model_, kin_, q_ref_, jacobian_);
  constexpr double kUnbounded = 1e3;
  dynamics::joint_rate_bounds(model_, q_ref_, JointVector::Constant(n, kUnbounded), qddot_max_,
                              period_s_, bounds_);
  dynamics::sns_velocity_ik(jacobian_, v_cmd, bounds_, sns_);

  // Flow prescaling.
  double scale = sns_.task_scale;
  out.limit = sns_.task_scale < 1.0 - 1e-9 ? scaling::ActiveLimit::kJointLimit
                                           : scaling::ActiveLimit::kNone;
  scaling::flow_prescale(model_, dc_dq_, sns_.qdot, flow_reserve_, prescale_);
  out.flow_demand_m3_s = prescale_.flow_demand_m3_s;
  if (options_.flow_prescaling && prescale_.scale < 1.0) {
    scale *= prescale_.scale;
    out.limit = prescale_.limit;
  }
  out.qdot_ref = sns_.qdot * (options_.flow_prescaling ? prescale_.scale : 1.0);
  out.scale = v_cmd.norm() > 0.0 ? scale : 1.0;
  out.ref_tip_velocity_m_s = jacobian_ * out.qdot_ref;

  // Reference integration, kept inside the joint ranges.
  for (int i = 0; i < n; ++i) {
    const auto& joint = model_.joints[static_cast<std::size_t>(i)];
    q_ref_[i] = std::clamp(q_ref_[i] + out.qdot_ref[i] * period_s_, joint.q_min, joint.q_max);
  }
  out.q_ref = q_ref_;

  // Valve commands.
  dynamics::cylinder_lengths(model_, q_ref_, c_ref_);
  dynamics::cylinder_lengths(model_, state.q, c_meas_);
  for (int i = 0; i < n; ++i) valve_in_.velocity_ref_m_s[i] = dc_dq_[i] * out.qdot_ref[i];
  c_ref_history_[history_head_] = c_ref_;
  history_head_ = (history_head_ + 1) % c_ref_history_.size();
  valve_in_.position_error_m = c_ref_history_[history_head_] - c_meas_;  // oldest entry
  valves_.update(valve_in_, out.valves);
  return ControllerStatus::kRunning;
}

}  // namespace craneassist::app
