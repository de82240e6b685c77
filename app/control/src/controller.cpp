#include "craneassist/control/controller.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/pendulum.hpp"
#include "craneassist/scaling/scaling_filter.hpp"

namespace craneassist::control {
namespace {

// The rated capacity limiter's thresholds on the load-moment ratio (docs/loads.md).
constexpr double kOverloadWarning = 0.9;
constexpr double kOverloadTrip = 1.0;
constexpr double kOverloadRelease = 0.95;
// Overloaded, a motion whose radial share (d reach / d path) is above this raises the moment.
constexpr double kOutwardShare = 0.02;
// The dynamics' payload follows the scale in steps of this (kg).
constexpr double kPayloadModelStepKg = 0.5;
// A chamber at this share of the load-holding valves' setting is at their port relief.
constexpr double kReliefShare = 0.99;

// A tip's horizontal distance from the slew axis (crane frame: y up), the load chart's reach.
double reach_of(const Eigen::Vector3d& tip) {
  return std::hypot(tip.x(), tip.z());
}

}  // namespace

const char* to_string(ScalingMode mode) {
  switch (mode) {
    case ScalingMode::kFull:
      return "full";
    case ScalingMode::kFlowOnly:
      return "flow";
    case ScalingMode::kNone:
      return "none";
  }
  return "?";
}

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

Controller::Controller(const config::CraneConfig& config, const ControllerOptions& options)
    : model_(config.model),
      options_(options),
      period_s_(1.0 / config.control.rate_hz),
      flow_reserve_(config.control.flow_reserve),
      tracking_error_ok_m_(config.scaling.tracking_error_ok_m),
      tracking_alpha_(period_s_ / (config.scaling.tracking_error_filter_s + period_s_)),
      // The live loop keeps every section under feedback: the activation rule is for executing
      // planned trajectories (trajectory_runner.hpp), whose at-rest cylinders the planner counts
      // as closed.
      follower_(config.model, config.control.position_gain_1_s, period_s_),
      // The full scaling keeps the reserve on both the pump flow and the cylinder speeds
      // (path_speed_limits), the flow-only prescaling on the flow only (flow_prescale).
      polytope_settings_{.flow_reserve = config.control.flow_reserve,
                         .cylinder_speed_reserve = options.mode == ScalingMode::kFull
                                                       ? config.control.flow_reserve
                                                       : 0.0},
      polytope_(config.model.dof(), 3) {
  follower_.set_command_period(options.valve_command_period_s);
  const int n = model_.dof();
  rest_speed_m_s_ = config.control.rest_speed_m_s;
  hold_error_m_ = config.control.activation_error_m;
  rest_timeout_cycles_ = std::lround(config.control.rest_timeout_s / period_s_);
  // At rest for the valves' lag: whatever was commanded before has arrived.
  rest_confirm_cycles_ = std::max(
      1L, std::lround((model_.valves.delay_s + model_.valves.time_constant_s) / period_s_));
  rest_arms_.setZero(n);
  q_ref_ = config.simulation.q_initial;
  dc_dq_.setZero(n);
  qddot_max_.setZero(n);
  polytope_arms_.setZero(n);
  chart_ = config.load_chart;
  deceleration_max_ = config.scaling.deceleration_max_m_s2;
  jerk_max_ = config.scaling.jerk_max_m_s3;
  sway_damping_ = config.scaling.sway_damping && model_.grapple.hangs();
  sway_measured_ = config.scaling.sway_frequency_measured;
  known_payload_kg_ = dynamics::payload_mass_kg(model_);
  dynamics::PayloadEstimatorSettings scale;
  scale.period_s = period_s_;
  estimator_ = std::make_unique<dynamics::PayloadEstimator>(model_, scale);
  if (options_.mode == ScalingMode::kFull) {
    terms_ = std::make_unique<dynamics::RigidBodyTerms>(model_);
    tip_path_ = std::make_unique<scaling::TipPath>(model_, tip_path_config(config));
    scaler_ = std::make_unique<scaling::TipScaler>(model_, tip_scaler_config(config), *terms_);
  }
}

Controller::~Controller() = default;

void Controller::set_valve_command_period(double period_s) {
  options_.valve_command_period_s = period_s;
  follower_.set_command_period(period_s);
}

void Controller::reset(const valves::MachineState& state) {
  q_ref_ = state.q;
  follower_.reset(q_ref_);
  tip_error_filtered_m_ = 0.0;
  neutral_ = false;
  refusing_ = false;
  settle_cycles_ = rest_cycles_ = 0;
  stop_end_ = StopEnd::kNone;
  if (tip_path_) tip_path_->reset();
  if (scaler_) scaler_->reset();
}

void Controller::update_load(const valves::MachineState& state, ControllerOutput& out) noexcept {
  LoadOutput& load = out.load;
  const int n = model_.dof();
  const bool state_ok =
      state.valid && state.q.size() == n && state.q.allFinite() && state.qdot.allFinite();
  const auto& est = estimator_->update(state_ok, state.q, state.qdot, state.chamber_pressures,
                                       state.pressure_a_pa, state.pressure_b_pa);
  if (state_ok) {
    load.reach_m = reach_of(dynamics::tip_position(model_, kin_, state.q));
  }
  load.rated_kg = chart_.empty() ? 0.0 : chart_.rated_kg_at(load.reach_m);
  load.weighed = std::isfinite(est.sigma_kg);
  if (options_.payload_known) {
    // Told: the config's payload, and on a simulator every change the run makes to it (a
    // replay's load_kg rows).
    if (std::isfinite(state.payload_truth_kg)) known_payload_kg_ = state.payload_truth_kg;
    load.estimate_kg = known_payload_kg_;
    load.sigma_kg = 0.0;
    load.converged = true;
    load.weighed = true;
    load.model_kg = known_payload_kg_;
  } else {
    load.estimate_kg = est.mass_kg;
    load.sigma_kg = est.sigma_kg;
    load.converged = est.converged;
    load.model_kg = chart_.empty() ? est.mass_kg : est.conservative_kg(load.rated_kg);
  }
  if (terms_ && std::abs(load.model_kg - terms_->payload_mass()) > kPayloadModelStepKg) {
    terms_->set_payload_mass(load.model_kg);
  }
  // The rated capacity limiter, on the scale's estimate.
  load.moment_ratio = load.rated_kg > 0.0 ? load.estimate_kg / load.rated_kg : 0.0;
  if (load.moment_ratio >= kOverloadTrip) overload_ = true;
  if (load.moment_ratio < kOverloadRelease) overload_ = false;
  load.overload = overload_;
  load.warning = load.moment_ratio >= kOverloadWarning;
  load.relief = false;
  if (state_ok && state.chamber_pressures && state.pressure_a_pa.size() == n &&
      state.pressure_b_pa.size() == n) {
    const double relief = kReliefShare * dynamics::load_holding_relief_pa(model_);
    for (int i = 0; i < n; ++i) {
      load.relief =
          load.relief || state.pressure_a_pa[i] >= relief || state.pressure_b_pa[i] >= relief;
    }
  }
  load.refused = false;
}

ControllerStatus Controller::update(const valves::MachineState& state, const Eigen::Vector3d& v_cmd,
                                    ControllerOutput& out) noexcept {
  const int n = model_.dof();
  const bool state_ok =
      state.valid && state.q.size() == n && state.q.allFinite() && state.qdot.allFinite();
  const bool command_ok = v_cmd.allFinite();
  const bool stale = !state_ok || !command_ok;
  out.flow_demand_m3_s = 0.0;
  // Resuming after a stop with neutral valves: the machine stood on its holding valves, so the
  // reference starts again from where it is measured (no P-feedback jump towards the old one).
  if (neutral_ && !stale) reset(state);

  update_load(state, out);
  const JointVector q_resolved = q_ref_;  // the cycle resolves here, then integrates q_ref_
  if (options_.mode == ScalingMode::kFull) {
    update_full(state, command_ok ? v_cmd : Eigen::Vector3d::Zero(), stale, out);
  } else if (stale) {
    out.qdot_ref.setZero(n);
    out.ref_tip_velocity_m_s.setZero();
    out.scale = 0.0;
    out.limit = scaling::ActiveLimit::kStaleInput;
    out.s = out.sdot = out.sddot = out.sdddot = out.sddot_min = out.sddot_max = 0.0;
  } else {
    update_rate_prescaled(v_cmd, out);
  }
  out.q_ref = q_ref_;
  update_polytope(q_resolved, command_ok ? v_cmd : Eigen::Vector3d::Zero(), stale, out);

  // A failed dynamics step stops the reference as a stale input does (the scaler's target is 0).
  const bool stopping = stale || dynamics_failed();
  const bool at_rest = out.qdot_ref.isZero(0.0) && out.sddot == 0.0 &&
                       (options_.mode != ScalingMode::kFull || scaler_out_.at_rest);
  if (stopping && at_rest) return finish_stop(state, state_ok, out);
  settle_cycles_ = rest_cycles_ = 0;
  stop_end_ = StopEnd::kNone;
  out.stop_end = StopEnd::kNone;
  // A stop has no dead-band lead: a feedback correction that changes side while the crane
  // decelerates crosses the band at the slew-rate limit, never by a full opening against the
  // motion (on a spool slower than the model the lead would ask for one).
  follower_.update(q_ref_, out.qdot_ref, state_ok ? &state.q : nullptr, out.valves, !stopping);
  return stopping ? ControllerStatus::kStopping : ControllerStatus::kRunning;
}

bool Controller::measured_at_rest(const valves::MachineState& state) noexcept {
  dynamics::tip_jacobian(model_, kin_, state.q, rest_jacobian_);
  if (!((rest_jacobian_ * state.qdot).norm() < rest_speed_m_s_)) return false;
  dynamics::cylinder_arms(model_, state.q, rest_arms_);
  for (int i = 0; i < model_.dof(); ++i) {
    if (!(std::abs(rest_arms_[i] * state.qdot[i]) < rest_speed_m_s_)) return false;
  }
  return true;
}

ControllerStatus Controller::finish_stop(const valves::MachineState& state, bool state_ok,
                                         ControllerOutput& out) noexcept {
  // The reference is at rest; the machine may still move (the valves' lag, a load running on).
  // It settles on P feedback at the reference until it is measured at rest for the valves' lag,
  // or until the timeout; then every valve ramps to neutral.
  if (stop_end_ == StopEnd::kNone) {
    if (!state_ok) {
      stop_end_ = StopEnd::kUnmeasured;
    } else {
      rest_cycles_ = measured_at_rest(state) ? rest_cycles_ + 1 : 0;
      if (rest_cycles_ >= rest_confirm_cycles_) {
        stop_end_ = StopEnd::kAtRest;
      } else if (++settle_cycles_ > rest_timeout_cycles_) {
        stop_end_ = StopEnd::kTimeout;
      }
    }
  }
  out.stop_end = stop_end_;
  if (stop_end_ == StopEnd::kNone) {
    follower_.hold(q_ref_, state.q, hold_error_m_, out.valves);
    return ControllerStatus::kStopping;
  }
  neutral_ = follower_.neutral(out.valves);
  return neutral_ ? ControllerStatus::kStopped : ControllerStatus::kStopping;
}

void Controller::update_polytope(const JointVector& q, const Eigen::Vector3d& v_cmd, bool stale,
                                 ControllerOutput& out) noexcept {
  dynamics::cylinder_arms(model_, q, polytope_arms_);
  dynamics::tip_jacobian(model_, kin_, q, polytope_jacobian_);
  dynamics::joint_velocity_set(model_, q, polytope_arms_, polytope_settings_, polytope_set_);
  polytope_.update(polytope_set_, polytope_jacobian_);
  polytope_.build_hull();
  out.polytope_dim = polytope_.dimension();
  out.polytope_volume_m3_s3 = polytope_.volume();
  out.polytope_area_m2_s2 = polytope_.area();
  const double stick = v_cmd.norm();
  if (stick > 0.0) stick_direction_ = v_cmd / stick;
  out.avail_speed_m_s = polytope_.max_speed(stick_direction_);
  // Along the joint motion the cycle chose: the full scaling's f' (J f' = u, per unit path
  // speed), the others' resolution of the command.
  out.avail_speed_resolved_m_s = 0.0;
  // A zero f' (the resolution gives up on u: a singular pose) has no speed along it.
  if (options_.mode == ScalingMode::kFull) {
    const JointVector& f1 = tip_out_.geometry.f1;
    if (!f1.isZero(0.0)) out.avail_speed_resolved_m_s = dynamics::speed_along(polytope_set_, f1);
  } else if (!stale && stick > 0.0) {
    const double tip_speed = (polytope_jacobian_ * sns_.qdot).norm();
    if (tip_speed > 0.0) {
      out.avail_speed_resolved_m_s = dynamics::speed_along(polytope_set_, sns_.qdot) * tip_speed;
    }
  }
}

bool Controller::dynamics_failed() const noexcept {
  return options_.mode == ScalingMode::kFull && scaler_out_.dynamics_failed;
}

void Controller::update_full(const valves::MachineState& state, const Eigen::Vector3d& v_cmd,
                             bool stale, ControllerOutput& out) noexcept {
  // Tracking error of the measured tip against the reference of one valve delay ago, filtered.
  const bool state_ok = state.valid && state.q.size() == model_.dof() && state.q.allFinite();
  if (state_ok) {
    const Eigen::Vector3d tip_meas = dynamics::tip_position(model_, kin_, state.q);
    const Eigen::Vector3d tip_ref =
        dynamics::tip_position(model_, kin_, follower_.delayed_reference_q());
    const double error = (tip_ref - tip_meas).norm();
    tip_error_filtered_m_ += tracking_alpha_ * (error - tip_error_filtered_m_);
  }

  // The present cylinder forces, from last cycle's dynamics terms (min-ls-power resolves the
  // redundancy at the current loads); unknown before the first cycle and after a failed step.
  const Eigen::Vector3d u = scaler_->direction(v_cmd);
  scaling::TipPathInput path_in;
  path_in.direction = u;
  path_in.sdot = scaler_->speed();
  path_in.intended_speed = stale ? path_in.sdot : scaler_->intended_speed(v_cmd);
  path_in.forces_known = scaler_out_.terms.b.size() == model_.dof() && !scaler_out_.dynamics_failed;
  if (path_in.forces_known) {
    dynamics::cylinder_arms(model_, q_ref_, dc_dq_);
    path_in.cylinder_force = scaler_out_.terms.b.cwiseQuotient(dc_dq_);
  }
  tip_path_->update(q_ref_, path_in, tip_out_);
  scaling::TipScalerInput in = tip_scaler_input(v_cmd, u, tip_out_, stale);
  in.tracking_factor = scaling::tracking_factor(tip_error_filtered_m_, tracking_error_ok_m_);
  if (sway_damping_) {
    // The swing's frequency with the load the scale has found (the rated load before it has),
    // tuned to the swing the machine's sensor measures (where it has one, and until then the
    // model's): the model's times the ratio of its period to the measured one.
    const double load_kg =
        std::isfinite(out.load.estimate_kg) ? out.load.estimate_kg : out.load.model_kg;
    const dynamics::Pendulum pendulum = dynamics::grapple_pendulum(model_, load_kg);
    const double model_period = pendulum.period_s();
    if (sway_measured_) {
      swing_frequency_.update(state.t_s, state.swing_radial_rad, state.swing_tangential_rad,
                              scaler_out_.acceleration.norm(), model_period);
    }
    const double tuned = sway_measured_ ? swing_frequency_.ratio() : 1.0;
    in.sway_omega_rad_s = pendulum.omega_rad_s * tuned;
    in.sway_zeta = pendulum.zeta;
    out.sway_model_period_s = model_period;
    out.sway_period_s = model_period / tuned;
    out.sway_measured_periods = sway_measured_ ? swing_frequency_.measured() : 0;
  }
  // The rated capacity limiter: a motion that takes the load further out (raises the load
  // moment) slows to rest when the crane is overloaded, or when the moment would pass the chart
  // where a stop from the present speed ends (braking ahead of the chart); once refused it stays
  // refused while the stick keeps pushing out and the moment is within 5 % of the chart. A
  // motion that brings the load in, or keeps its reach, stays free.
  if (!chart_.empty()) {
    const Eigen::Vector3d tip = dynamics::tip_position(model_, kin_, q_ref_);
    const double reach = reach_of(tip);
    const double outwards = reach > 0.0 ? (tip.x() * u.x() + tip.z() * u.z()) / reach : 0.0;
    const bool out_bound = outwards > kOutwardShare && v_cmd.norm() > 0.0;
    const double stop = scaling::braking_distance(
        scaler_->speed(), std::max(scaler_out_.sddot, 0.0), deceleration_max_, jerk_max_);
    const double rated_ahead = chart_.rated_kg_at(reach + std::max(outwards, 0.0) * stop);
    const double ratio_ahead = rated_ahead > 0.0 ? out.load.estimate_kg / rated_ahead : 0.0;
    refusing_ = out_bound && (out.load.overload || ratio_ahead >= kOverloadTrip ||
                              (refusing_ && out.load.moment_ratio >= kOverloadRelease));
    in.overload_refused = refusing_;
    out.load.refused = refusing_;
  }
  scaler_->update(q_ref_, tip_out_.geometry, in, scaler_out_);

  // The reference moves along u by the tip displacement of this cycle.
  const auto& g = tip_out_.geometry;
  const double ds = scaler_out_.ds;
  for (int i = 0; i < model_.dof(); ++i) {
    const auto& joint = model_.joints[static_cast<std::size_t>(i)];
    q_ref_[i] =
        std::clamp(q_ref_[i] + g.f1[i] * ds + 0.5 * g.f2[i] * ds * ds, joint.q_min, joint.q_max);
  }
  const double along = scaler_out_.velocity.dot(u);
  out.qdot_ref = g.f1 * along;
  out.ref_tip_velocity_m_s = u * along;  // = J(q_ref) qdot_ref
  const double v_cmd_norm = v_cmd.norm();
  // The factor the limits put on the command, 0..1: while the reference decelerates to a
  // command that fell (a released or eased stick) it is faster than the command, unscaled.
  out.scale = v_cmd_norm > 0.0 ? std::clamp(scaler_out_.sdot / v_cmd_norm, 0.0, 1.0) : 1.0;
  out.flow_demand_m3_s = scaler_out_.speed.flow_per_speed_m3 * v_cmd_norm;
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
}

void Controller::update_rate_prescaled(const Eigen::Vector3d& v_cmd,
                                       ControllerOutput& out) noexcept {
  const int n = model_.dof();
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

  double scale = sns_.task_scale;
  out.limit = sns_.task_scale < 1.0 - 1e-9 ? scaling::ActiveLimit::kJointLimit
                                           : scaling::ActiveLimit::kNone;
  scaling::flow_prescale(model_, dc_dq_, sns_.qdot, flow_reserve_, prescale_);
  out.flow_demand_m3_s = prescale_.flow_demand_m3_s;
  const bool prescale = options_.mode == ScalingMode::kFlowOnly;
  if (prescale && prescale_.scale < 1.0) {
    scale *= prescale_.scale;
    out.limit = prescale_.limit;
  }
  out.qdot_ref = sns_.qdot * (prescale ? prescale_.scale : 1.0);
  out.scale = v_cmd.norm() > 0.0 ? scale : 1.0;
  out.ref_tip_velocity_m_s = jacobian_ * out.qdot_ref;
  for (int i = 0; i < n; ++i) {
    const auto& joint = model_.joints[static_cast<std::size_t>(i)];
    q_ref_[i] = std::clamp(q_ref_[i] + out.qdot_ref[i] * period_s_, joint.q_min, joint.q_max);
  }
  out.s = out.sdot = out.sddot = out.sdddot = out.sddot_min = out.sddot_max = 0.0;
  out.tip_error_m = 0.0;
  out.ref_power_w = 0.0;
}

}  // namespace craneassist::control
