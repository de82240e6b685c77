#include "craneassist/control/tip_stage.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/pendulum.hpp"
#include "craneassist/scaling/scaling_filter.hpp"
#include "craneassist/scaling/speed_caps.hpp"

namespace craneassist::control {
namespace {

// Overloaded, a motion whose radial share (d reach / d path) is above this raises the moment.
constexpr double kOutwardShare = 0.02;
// The dynamics' payload follows the scale in steps of this (kg).
constexpr double kPayloadModelStepKg = 0.5;

}  // namespace

scaling::TipPathConfig tip_path_config(const config::CraneConfig& config) {
  scaling::TipPathConfig path;
  path.period_s = 1.0 / config.control.rate_hz;
  path.jerk_max = config.scaling.jerk_max_m_s3;
  path.deceleration_max = config.scaling.deceleration_max_m_s2;
  path.flow_reserve = config.control.flow_reserve;
  path.resolution = config.redundancy.resolution;
  return path;
}

scaling::TipScalerConfig tip_scaler_config(const config::CraneConfig& config) {
  const auto& sc = config.scaling;
  scaling::TipScalerConfig scaler;
  scaler.period_s = 1.0 / config.control.rate_hz;
  scaler.jerk_max = sc.jerk_max_m_s3;
  scaler.acceleration_max = sc.acceleration_max_m_s2;
  scaler.deceleration_max = sc.deceleration_max_m_s2;
  scaler.normal_acceleration_max = sc.direction_change_acceleration_m_s2;
  scaler.flow_reserve = config.control.flow_reserve;
  scaler.power_bound = sc.power_bound;
  scaler.power_reserve = sc.power_reserve;
  // The slowest swing: the grapple with the heaviest load the config's range allows (or empty,
  // when the load hangs above the grapple's centre of mass), with margin.
  const auto& model = config.model;
  const double slowest = std::min(dynamics::grapple_pendulum(model, 0.0).omega_rad_s,
                                  dynamics::grapple_pendulum(model, 1e5).omega_rad_s);
  if (slowest > 0.0) scaler.sway_max_delay_s = 1.5 * scaling::SwayShaper::delay_s(slowest, 0.0);
  return scaler;
}

scaling::TipScalerInput tip_scaler_input(const Eigen::Vector3d& command, const Eigen::Vector3d& u,
                                         const scaling::TipPathOutput& path, bool stale) {
  scaling::TipScalerInput in;
  in.command = command;
  in.direction = u;
  in.sdot_joint_limit = path.sdot_joint_limit;
  in.end_distance_m = path.end_distance_m;
  in.stop_deceleration_m_s2 = path.stop_deceleration_m_s2;
  in.stop_jerk_m_s3 = path.stop_jerk_m_s3;
  in.near_singular = path.near_singular;
  in.stale_input = stale;
  return in;
}

std::unique_ptr<TipStage> make_tip_stage(const config::CraneConfig& config, ScalingMode mode) {
  if (mode == ScalingMode::kFull) return std::make_unique<PathScalingStage>(config);
  return std::make_unique<PrescalingStage>(config, mode == ScalingMode::kFlowOnly);
}

// ---- the full scaling ----

PathScalingStage::PathScalingStage(const config::CraneConfig& config)
    : model_(config.model),
      tracking_error_ok_m_(config.scaling.tracking_error_ok_m),
      tracking_alpha_((1.0 / config.control.rate_hz) /
                      (config.scaling.tracking_error_filter_s + 1.0 / config.control.rate_hz)),
      terms_(std::make_unique<dynamics::RigidBodyTerms>(config.model)),
      tip_path_(config.model, tip_path_config(config)),
      scaler_(config.model, tip_scaler_config(config), *terms_),
      q_ref_(config.simulation.q_initial),
      chart_(config.load_chart),
      deceleration_max_(config.scaling.deceleration_max_m_s2),
      jerk_max_(config.scaling.jerk_max_m_s3),
      sway_damping_(config.scaling.sway_damping && config.model.grapple.hangs()),
      sway_measured_(config.scaling.sway_frequency_measured) {
  dc_dq_.setZero(model_.dof());
  path_in_.cylinder_force.setZero(model_.dof());
}

void PathScalingStage::reset(const JointVector& q) noexcept {
  q_ref_ = q;
  tip_error_filtered_m_ = 0.0;
  refusing_ = false;
  tip_path_.reset();
  scaler_.reset();
}

void PathScalingStage::set_payload_model_kg(double kg) noexcept {
  if (std::abs(kg - terms_->payload_mass()) > kPayloadModelStepKg) terms_->set_payload_mass(kg);
}

// Tracking error of the measured tip against the reference of one valve delay ago, filtered.
void PathScalingStage::update_tracking(const TipStageInput& in) noexcept {
  const valves::MachineState& state = *in.state;
  const bool state_ok = state.valid && state.q.size() == model_.dof() && state.q.allFinite();
  if (!state_ok) return;
  const Eigen::Vector3d tip_meas = dynamics::tip_position(model_, kin_, state.q);
  const Eigen::Vector3d tip_ref = dynamics::tip_position(model_, kin_, *in.delayed_q_ref);
  const double error = (tip_ref - tip_meas).norm();
  tip_error_filtered_m_ += tracking_alpha_ * (error - tip_error_filtered_m_);
}

// The swing's frequency with the load the scale has found (the rated load before it has), tuned
// to the swing the machine's sensor measures (where it has one, and until then the model's):
// the model's times the ratio of its period to the measured one.
void PathScalingStage::update_sway(const TipStageInput& in, ControllerOutput& out) noexcept {
  if (!sway_damping_) return;
  const LoadOutput& load = *in.load;
  const double load_kg = std::isfinite(load.estimate_kg) ? load.estimate_kg : load.model_kg;
  const dynamics::Pendulum pendulum = dynamics::grapple_pendulum(model_, load_kg);
  const double model_period = pendulum.period_s();
  if (sway_measured_) {
    const valves::MachineState& state = *in.state;
    swing_frequency_.update(state.t_s, state.swing_radial_rad, state.swing_tangential_rad,
                            scaler_out_.acceleration.norm(), model_period);
  }
  const double tuned = sway_measured_ ? swing_frequency_.ratio() : 1.0;
  scaler_in_.sway_omega_rad_s = pendulum.omega_rad_s * tuned;
  scaler_in_.sway_zeta = pendulum.zeta;
  out.sway_model_period_s = model_period;
  out.sway_period_s = model_period / tuned;
  out.sway_measured_periods = sway_measured_ ? swing_frequency_.measured() : 0;
}

// The rated capacity limiter: a motion that takes the load further out (raises the load moment)
// slows to rest when the crane is overloaded, or when the moment would pass the chart where a
// stop from the present speed ends (braking ahead of the chart); once refused it stays refused
// while the stick keeps pushing out and the moment is within 5 % of the chart. A motion that
// brings the load in, or keeps its reach, stays free.
bool PathScalingStage::refuse_outward(const Eigen::Vector3d& command, const Eigen::Vector3d& u,
                                      const LoadOutput& load) noexcept {
  const Eigen::Vector3d tip = dynamics::tip_position(model_, kin_, q_ref_);
  const double reach = horizontal_reach_m(tip);
  const double outwards = reach > 0.0 ? (tip.x() * u.x() + tip.z() * u.z()) / reach : 0.0;
  const bool out_bound = outwards > kOutwardShare && command.norm() > 0.0;
  const double stop = scaling::braking_distance(scaler_.speed(), std::max(scaler_out_.sddot, 0.0),
                                                deceleration_max_, jerk_max_);
  const double rated_ahead = chart_.rated_kg_at(reach + std::max(outwards, 0.0) * stop);
  const double ratio_ahead = rated_ahead > 0.0 ? load.estimate_kg / rated_ahead : 0.0;
  refusing_ = out_bound && (load.overload || ratio_ahead >= kOverloadTrip ||
                            (refusing_ && load.moment_ratio >= kOverloadRelease));
  return refusing_;
}

TipStageStatus PathScalingStage::update(const TipStageInput& in, ControllerOutput& out) noexcept {
  const int n = model_.dof();
  const Eigen::Vector3d& command = in.command;
  update_tracking(in);

  // The direction of this cycle and its resolution at the reference, at the present cylinder
  // forces (from last cycle's dynamics terms: min-ls-power resolves the redundancy at the
  // current loads; unknown before the first cycle and after a failed step).
  const Eigen::Vector3d u = scaler_.direction(command);
  path_in_.direction = u;
  path_in_.sdot = scaler_.speed();
  path_in_.intended_speed = in.stale ? path_in_.sdot : scaler_.intended_speed(command);
  path_in_.forces_known = scaler_out_.terms.b.size() == n && !scaler_out_.dynamics_failed;
  if (path_in_.forces_known) {
    dynamics::cylinder_arms(model_, q_ref_, dc_dq_);
    path_in_.cylinder_force = scaler_out_.terms.b.cwiseQuotient(dc_dq_);
  }
  tip_path_.update(q_ref_, path_in_, tip_out_);

  // The scaler's input: the path's findings, the slow-downs, the swing, the limiter.
  scaler_in_ = tip_scaler_input(command, u, tip_out_, in.stale);
  scaler_in_.tracking_factor =
      scaling::tracking_factor(tip_error_filtered_m_, tracking_error_ok_m_);
  update_sway(in, out);
  if (!chart_.empty()) {
    scaler_in_.overload_refused = refuse_outward(command, u, *in.load);
    out.load.refused = refusing_;
  }
  scaler_.update(q_ref_, tip_out_.geometry, scaler_in_, scaler_out_);

  // The reference moves along u by the tip displacement of this cycle.
  const auto& g = tip_out_.geometry;
  const double ds = scaler_out_.ds;
  for (int i = 0; i < n; ++i) {
    const auto& joint = model_.joints[static_cast<std::size_t>(i)];
    q_ref_[i] =
        std::clamp(q_ref_[i] + g.f1[i] * ds + 0.5 * g.f2[i] * ds * ds, joint.q_min, joint.q_max);
  }
  const double along = scaler_out_.velocity.dot(u);
  out.qdot_ref = g.f1 * along;
  out.ref_tip_velocity_m_s = u * along;  // = J(q_ref) qdot_ref
  const double command_norm = command.norm();
  // The factor the limits put on the command, 0..1: while the reference decelerates to a
  // command that fell (a released or eased stick) it is faster than the command, unscaled.
  out.scale = command_norm > 0.0 ? std::clamp(scaler_out_.sdot / command_norm, 0.0, 1.0) : 1.0;
  out.flow_demand_m3_s = scaler_out_.speed.flow_per_speed_m3 * command_norm;
  out.limit = scaler_out_.limit;
  out.s = scaler_out_.s;
  out.sdot = scaler_out_.sdot;
  out.sddot = scaler_out_.at_rest ? 0.0 : scaler_out_.sddot;
  out.sdddot = scaler_out_.sdddot;
  out.sddot_min = scaler_out_.bounds.sddot_min;
  out.sddot_max = scaler_out_.bounds.sddot_max;
  out.tip_error_m = tip_error_filtered_m_;
  // No prediction without the dynamics.
  out.ref_power_w =
      scaler_out_.dynamics_failed
          ? 0.0
          : scaling::pump_power(model_, g, scaler_out_.terms, std::abs(along), scaler_out_.sddot);
  out.q_ref = q_ref_;
  const bool at_rest = out.qdot_ref.isZero(0.0) && out.sddot == 0.0 && scaler_out_.at_rest;
  return at_rest ? TipStageStatus::kAtRest : TipStageStatus::kMoving;
}

// ---- the baselines ----

PrescalingStage::PrescalingStage(const config::CraneConfig& config, bool prescale)
    : model_(config.model),
      prescale_(prescale),
      period_s_(1.0 / config.control.rate_hz),
      flow_reserve_(config.control.flow_reserve) {
  const int n = model_.dof();
  dc_dq_.setZero(n);
  qddot_max_.setZero(n);
  q_ref_ = config.simulation.q_initial;
  motion_.setZero(n);
}

TipStageStatus PrescalingStage::update(const TipStageInput& in, ControllerOutput& out) noexcept {
  const int n = model_.dof();
  out.s = out.sdot = out.sddot = out.sdddot = out.sddot_min = out.sddot_max = 0.0;
  out.tip_error_m = 0.0;
  out.ref_power_w = 0.0;
  motion_.setZero(n);
  tip_speed_ = 0.0;
  if (in.stale) {  // the reference stops at once
    out.qdot_ref.setZero(n);
    out.ref_tip_velocity_m_s.setZero();
    out.scale = 0.0;
    out.limit = scaling::ActiveLimit::kStaleInput;
    out.q_ref = q_ref_;
    return TipStageStatus::kAtRest;
  }
  const Eigen::Vector3d& v_cmd = in.command;
  dynamics::cylinder_arms(model_, q_ref_, dc_dq_);
  for (int i = 0; i < n; ++i) {
    qddot_max_[i] = model_.cylinders[static_cast<std::size_t>(i)].a_max_m_s2 / std::abs(dc_dq_[i]);
  }
  // Redundancy resolution. Its bounds only keep the joints off their ends; speed limits are the
  // prescaling's job, applied uniformly.
  dynamics::tip_jacobian(model_, kin_, q_ref_, jacobian_);
  constexpr double kUnbounded = 1e3;
  dynamics::joint_rate_bounds(model_, q_ref_, JointVector::Constant(n, kUnbounded), qddot_max_,
                              period_s_, bounds_);
  dynamics::sns_velocity_ik(jacobian_, v_cmd, bounds_, sns_);
  if (v_cmd.norm() > 0.0) {
    motion_ = sns_.qdot;
    tip_speed_ = (jacobian_ * sns_.qdot).norm();
  }

  double scale = sns_.task_scale;
  out.limit = sns_.task_scale < 1.0 - 1e-9 ? scaling::ActiveLimit::kJointLimit
                                           : scaling::ActiveLimit::kNone;
  scaling::flow_prescale(model_, dc_dq_, sns_.qdot, flow_reserve_, prescale_result_);
  out.flow_demand_m3_s = prescale_result_.flow_demand_m3_s;
  if (prescale_ && prescale_result_.scale < 1.0) {
    scale *= prescale_result_.scale;
    out.limit = prescale_result_.limit;
  }
  out.qdot_ref = sns_.qdot * (prescale_ ? prescale_result_.scale : 1.0);
  out.scale = v_cmd.norm() > 0.0 ? scale : 1.0;
  out.ref_tip_velocity_m_s = jacobian_ * out.qdot_ref;
  for (int i = 0; i < n; ++i) {
    const auto& joint = model_.joints[static_cast<std::size_t>(i)];
    q_ref_[i] = std::clamp(q_ref_[i] + out.qdot_ref[i] * period_s_, joint.q_min, joint.q_max);
  }
  out.q_ref = q_ref_;
  return out.qdot_ref.isZero(0.0) ? TipStageStatus::kAtRest : TipStageStatus::kMoving;
}

}  // namespace craneassist::control
