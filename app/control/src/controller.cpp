#include "craneassist/control/controller.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/valve_table.hpp"

namespace craneassist::control {
namespace {

// A chamber at this share of the load-holding valves' setting is at their port relief.
constexpr double kReliefShare = 0.99;

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

Controller::Controller(const config::CraneConfig& config, const ControllerOptions& options)
    : config_(config),
      model_(config.model),
      options_(options),
      period_s_(1.0 / config.control.rate_hz),
      // The live loop keeps every section under feedback: the activation rule is for executing
      // planned trajectories (trajectory_runner.hpp), whose at-rest cylinders the planner counts
      // as closed.
      follower_(config.model, config.control.position_gain_1_s, period_s_),
      stage_(make_tip_stage(config, options.mode)) {
  follower_.set_command_period(options.valve_command_period_s);
  set_polytope(options.polytope);
  const int n = model_.dof();
  rest_speed_m_s_ = config.control.rest_speed_m_s;
  hold_error_m_ = config.control.activation_error_m;
  rest_timeout_cycles_ = std::lround(config.control.rest_timeout_s / period_s_);
  // At rest for the valves' lag: whatever was commanded before has arrived.
  rest_confirm_cycles_ =
      std::max(1L, std::lround(dynamics::longest_valve_lag_s(model_) / period_s_));
  rest_arms_.setZero(n);
  chart_ = config.load_chart;
  known_payload_kg_ = dynamics::payload_mass_kg(model_);
  dynamics::PayloadEstimatorSettings scale;
  scale.period_s = period_s_;
  estimator_ = std::make_unique<dynamics::PayloadEstimator>(model_, scale);
}

Controller::~Controller() = default;

void Controller::set_valve_command_period(double period_s) {
  options_.valve_command_period_s = period_s;
  follower_.set_command_period(period_s);
}

void Controller::set_polytope(bool on) {
  options_.polytope = on;
  if (on && !polytope_) polytope_ = std::make_unique<PolytopeProbe>(config_, options_.mode);
  if (!on) polytope_.reset();
}

void Controller::reset(const valves::MachineState& state) {
  stage_->reset(state.q);
  follower_.reset(state.q);
  neutral_ = false;
  settle_cycles_ = rest_cycles_ = 0;
  stop_end_ = StopEnd::kNone;
}

void Controller::update_load(const valves::MachineState& state, ControllerOutput& out) noexcept {
  LoadOutput& load = out.load;
  const int n = model_.dof();
  const bool state_ok =
      state.valid && state.q.size() == n && state.q.allFinite() && state.qdot.allFinite();
  const auto& est = estimator_->update(state_ok, state.q, state.qdot, state.chamber_pressures,
                                       state.pressure_a_pa, state.pressure_b_pa);
  if (state_ok) {
    load.reach_m = horizontal_reach_m(dynamics::tip_position(model_, kin_, state.q));
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
  stage_->set_payload_model_kg(load.model_kg);
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
  const Eigen::Vector3d command = command_ok ? v_cmd : Eigen::Vector3d::Zero();
  // The stage resolves at its reference, then integrates it; the polytope is of where it resolved.
  if (polytope_) q_resolved_ = stage_->q_ref();
  const TipStageInput stage_in{.command = command,
                               .stale = stale,
                               .state = &state,
                               .delayed_q_ref = &follower_.delayed_reference_q(),
                               .load = &out.load};
  const bool at_rest = stage_->update(stage_in, out) == TipStageStatus::kAtRest;
  if (polytope_) {
    polytope_->update(q_resolved_, command, stage_->resolved_motion(), stage_->resolved_tip_speed(),
                      out);
  }

  // A failed dynamics step stops the reference as a stale input does (the scaler's target is 0).
  const bool stopping = stale || stage_->dynamics_failed();
  if (stopping && at_rest) return finish_stop(state, state_ok, out);
  settle_cycles_ = rest_cycles_ = 0;
  stop_end_ = StopEnd::kNone;
  out.stop_end = StopEnd::kNone;
  // A stop has no dead-band lead: a feedback correction that changes side while the crane
  // decelerates crosses the band at the slew-rate limit, never by a full opening against the
  // motion (on a spool slower than the model the lead would ask for one).
  follower_.update(out.q_ref, out.qdot_ref, state_ok ? &state.q : nullptr, out.valves, !stopping);
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
    follower_.hold(out.q_ref, state.q, hold_error_m_, out.valves);
    return ControllerStatus::kStopping;
  }
  neutral_ = follower_.neutral(out.valves);
  return neutral_ ? ControllerStatus::kStopped : ControllerStatus::kStopping;
}

}  // namespace craneassist::control
