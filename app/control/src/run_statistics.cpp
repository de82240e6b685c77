#include "craneassist/control/run_statistics.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "craneassist/control/controller.hpp"

namespace craneassist::control {

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double na = a.norm(), nb = b.norm();
  if (na == 0.0 || nb == 0.0) return 0.0;
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

RunStatistics::RunStatistics(double period_s, const RunStatisticsOptions& options)
    : period_s_(period_s), options_(options), quality_(period_s) {
  const double window =
      period_s > 0.0
          ? std::round(std::min(options.position_window_s, options.steady_after_s) / period_s)
          : 1.0;
  window_ = static_cast<int>(std::clamp(window, 1.0, static_cast<double>(kMaxPositionWindow)));
  s_.position_window_s = window_ * period_s;
}

void RunStatistics::on_cycle(const CycleRecord& c) noexcept {
  const LogRow& row = c.row;
  const double t = c.time.t_s;
  const Eigen::Vector3d cmd(row.cmd[0], row.cmd[1], row.cmd[2]);
  const Eigen::Vector3d tip(row.tip[0], row.tip[1], row.tip[2]);
  const Eigen::Vector3d tip_v(row.tip_v[0], row.tip_v[1], row.tip_v[2]);
  const bool input_stop = !cmd.allFinite() && c.stop_cause == nullptr;  // not the loop's stop

  if (c.status != CycleStatus::kRunning) ++s_.stopped_cycles;
  s_.neutral_valve_cycles += c.status == CycleStatus::kStopped;
  s_.input_stop_cycles += input_stop;
  s_.peak_power_w = std::max(s_.peak_power_w, c.state.pump.power_w);
  s_.peak_flow_m3_s = std::max(s_.peak_flow_m3_s, c.state.pump.flow_m3_s);
  s_.pump_saturated_cycles += c.state.pump.limit != valves::PumpLimit::kNone;
  const double speed = tip_v.norm();
  s_.peak_tip_speed_m_s = std::max(s_.peak_tip_speed_m_s, speed);
  // The path over valid measurements only (an invalid one, e.g. a CAN fault, has no tip).
  if (c.time.k > 0 && c.state.valid && last_tip_valid_) s_.tip_path_m += (tip - last_tip_).norm();
  last_tip_ = tip;
  last_tip_valid_ = c.state.valid;
  const auto slot = [](long k) {
    return static_cast<std::size_t>(k % static_cast<long>(kMaxPositionWindow + 1));
  };
  tips_[slot(tip_count_)] = tip;
  tips_valid_[slot(tip_count_)] = c.state.valid && tip.allFinite();
  ++tip_count_;
  quality_.add(t, cmd, tip, tip_v);

  // Spool command steps from one cycle to the next (a command of another size restarts).
  const int n =
      static_cast<int>(std::min<Eigen::Index>(c.command.spool.size(), dynamics::kMaxJoints));
  double spool_step = 0.0;
  for (int i = 0; i < n && n == spool_count_; ++i) {
    if (std::isfinite(c.command.spool[i])) {
      spool_step = std::max(spool_step, std::abs(c.command.spool[i] - last_spool_[i]));
    }
  }
  s_.peak_spool_step = std::max(s_.peak_spool_step, spool_step);
  add_stop(c, speed, spool_step);
  for (int i = 0; i < n; ++i) last_spool_[i] = c.command.spool[i];
  spool_count_ = n;

  // The swing, and what the stick's last return to rest left of it.
  const bool stick_moving = cmd.allFinite() && cmd.norm() > 0.0;
  if (stick_moving_ && !stick_moving) {
    release_s_ = t;
    s_.swing.released = true;
    s_.swing.after_release_deg = 0.0;
  }
  if (stick_moving) s_.swing.released = false;
  stick_moving_ = stick_moving;
  if (const double swing = std::abs(c.state.swing_rad) * 180.0 / M_PI; std::isfinite(swing)) {
    s_.swing.measured = true;
    s_.swing.peak_deg = std::max(s_.swing.peak_deg, swing);
    swing_deg_[swing_count_ % kSwingRing] = swing;
    swing_t_[swing_count_ % kSwingRing] = t;
    ++swing_count_;
    if (s_.swing.released && t >= release_s_ + 1.0) {
      s_.swing.after_release_deg = std::max(s_.swing.after_release_deg, swing);
    }
  }

  const ControllerOutput* out = c.controller;
  if (out == nullptr) return;
  s_.swing.model_period_s = out->sway_model_period_s;
  s_.swing.period_s = out->sway_period_s;
  s_.swing.measured_periods = out->sway_measured_periods;
  s_.peak_path_jerk = std::max(s_.peak_path_jerk, std::abs(out->sdddot));
  add_load(t, speed, c.state, *out);
  ++s_.limit_cycles[static_cast<std::size_t>(out->limit)];
  if (!(cmd == last_cmd_ || (input_stop && !last_cmd_.allFinite()))) {
    last_cmd_ = cmd;
    cmd_since_s_ = t;
  }
  // Direction statistics: the reference has been on the command (direction blending done) for
  // the settling window, and the tip moves.
  const bool moving_cmd = cmd.norm() > 0.0;  // false for a non-finite command too
  if (!(moving_cmd && angle_deg(cmd, out->ref_tip_velocity_m_s) < 0.5)) {
    cmd_since_s_ = t + period_s_;  // not on the command yet: the window starts later
  }
  if (moving_cmd && speed > options_.min_speed_m_s && t - cmd_since_s_ >= options_.steady_after_s) {
    const double err = angle_deg(cmd, tip_v);
    s_.max_direction_error_deg = std::max(s_.max_direction_error_deg, err);
    sum_sq_direction_ += err * err;
    ++s_.direction_samples;
    const int bin = err < 10.0
                        ? static_cast<int>(err * 100.0)
                        : kFineBins + std::min(static_cast<int>(err - 10.0), kCoarseBins - 1);
    ++direction_bins_[static_cast<std::size_t>(std::clamp(bin, 0, kFineBins + kCoarseBins - 1))];
    // The displacement over the window lies within the steady command (window <= steady_after).
    const long now = tip_count_ - 1, then = now - window_;
    if (then >= 0 && tips_valid_[slot(now)] && tips_valid_[slot(then)]) {
      const double perr = angle_deg(cmd, tips_[slot(now)] - tips_[slot(then)]);
      s_.max_position_direction_error_deg = std::max(s_.max_position_direction_error_deg, perr);
      sum_sq_position_direction_ += perr * perr;
      ++position_samples_;
    }
  }
  if (moving_cmd && out->ref_tip_velocity_m_s.norm() > 1e-9) {
    s_.max_reference_direction_error_deg =
        std::max(s_.max_reference_direction_error_deg, angle_deg(cmd, out->ref_tip_velocity_m_s));
  }
}

void RunStatistics::add_load(double t, double tip_speed, const valves::MachineState& state,
                             const ControllerOutput& out) noexcept {
  constexpr double kSettledAfterS = 1.0;
  constexpr double kRestSpeed = 0.01, kMovingSpeed = 0.05;
  LoadSummary& l = s_.load;
  const LoadOutput& est = out.load;
  const bool truth = std::isfinite(state.payload_truth_kg);
  if (truth) {
    if (!l.truth_known || state.payload_truth_kg != l.truth_kg) {
      if (l.truth_known) ++l.truth_changes;
      truth_since_s_ = t;
    }
    l.truth_known = true;
    l.truth_kg = state.payload_truth_kg;
  }
  l.estimate_kg = est.estimate_kg;
  l.sigma_kg = est.sigma_kg;
  l.converged = est.converged;
  l.weighed = l.weighed || est.weighed;
  l.peak_moment_ratio = std::max(l.peak_moment_ratio, est.moment_ratio);
  l.warning_cycles += est.warning;
  l.overload_cycles += est.overload;
  l.refused_cycles += est.refused;
  l.relief_cycles += est.relief;
  if (truth && est.converged && t - truth_since_s_ >= kSettledAfterS && state.valid) {
    const double err = std::abs(est.estimate_kg - state.payload_truth_kg);
    if (tip_speed < kRestSpeed) {
      l.max_error_rest_kg = std::max(l.max_error_rest_kg, err);
      ++l.rest_samples;
    } else if (tip_speed > kMovingSpeed) {
      l.max_error_moving_kg = std::max(l.max_error_moving_kg, err);
      ++l.moving_samples;
    }
  }
}

void RunStatistics::add_stop(const CycleRecord& c, double tip_speed, double spool_step) noexcept {
  StopSummary& st = s_.stop;
  double load_pa = 0.0;
  if (c.state.valid) {
    for (Eigen::Index i = 0; i < c.state.load_pressure_pa.size(); ++i) {
      if (std::isfinite(c.state.load_pressure_pa[i])) {
        load_pa = std::max(load_pa, std::abs(c.state.load_pressure_pa[i]));
      }
    }
  }
  if (c.status == CycleStatus::kRunning) {
    in_stop_ = false;
    running_load_pressure_pa_ = load_pa;
    return;
  }
  if (!in_stop_) {  // a stop begins (or the run begins stopped)
    in_stop_ = true;
    stop_start_s_ = c.time.t_s;
    stop_steady_pa_ = running_load_pressure_pa_;
    stop_peak_pa_ = 0.0;
    stop_counted_ = false;
    for (int i = 0; i < spool_count_; ++i) stop_start_spool_[i] = last_spool_[i];
  }
  st.peak_spool_step = std::max(st.peak_spool_step, spool_step);
  stop_peak_pa_ = std::max(stop_peak_pa_, load_pa);
  for (int i = 0; i < spool_count_ && i < c.command.spool.size(); ++i) {
    const double u = c.command.spool[i];
    if (std::abs(u) >= 0.99 && u * stop_start_spool_[i] < 0.0) {
      ++st.full_reverse_cycles;
      break;
    }
  }
  // The first cycle with the valves neutral ends the stop.
  const ControllerOutput* out = c.controller;
  if (c.status != CycleStatus::kStopped || stop_counted_) return;
  ++st.stops;
  st.end = out != nullptr ? out->stop_end : StopEnd::kNone;
  st.tip_speed_at_neutral_m_s =
      c.state.valid ? tip_speed : std::numeric_limits<double>::quiet_NaN();
  if (std::isfinite(st.tip_speed_at_neutral_m_s)) {
    st.max_tip_speed_at_neutral_m_s =
        std::max(st.max_tip_speed_at_neutral_m_s, st.tip_speed_at_neutral_m_s);
  }
  st.time_s = c.time.t_s - stop_start_s_;
  st.timeouts += st.end == StopEnd::kTimeout;
  st.unmeasured += st.end == StopEnd::kUnmeasured;
  st.peak_load_pressure_pa = std::max(st.peak_load_pressure_pa, stop_peak_pa_);
  st.steady_load_pressure_pa = std::max(st.steady_load_pressure_pa, stop_steady_pa_);
  stop_counted_ = true;  // the stop goes on neutral until the next running cycle
}

void RunStatistics::on_finish(const CycleTime&, const valves::MachineState& state) {
  s_.energy_j = state.pump.energy_j;
}

RunSummary RunStatistics::summary(const LoopSummary& loop) const {
  RunSummary s = s_;
  s.feel = quality_.result();
  s.cycles = loop.cycles;
  s.duration_s = loop.duration_s;
  s.wall_time_s = loop.wall_time_s;
  s.machine_fault = loop.machine_fault;
  s.end_stop = loop.end_stop;
  s.stop_cycles = loop.stop_cycles;
  s.log_rows_dropped = loop.log_rows_dropped;
  // What still swings: the largest swing over the run's last second.
  const std::size_t kept = std::min(swing_count_, kSwingRing);
  if (kept > 0) {
    const double last_t = swing_t_[(swing_count_ - 1) % kSwingRing];
    for (std::size_t k = 0; k < kept; ++k) {
      const std::size_t at = (swing_count_ - 1 - k) % kSwingRing;
      if (swing_t_[at] < last_t - 1.0) break;
      s.swing.end_deg = std::max(s.swing.end_deg, swing_deg_[at]);
    }
  }
  s.rms_direction_error_deg =
      s.direction_samples > 0
          ? std::sqrt(sum_sq_direction_ / static_cast<double>(s.direction_samples))
          : 0.0;
  // The p95: the upper edge of the bin where the count passes 95 %.
  long seen = 0;
  for (int b = 0; b < kFineBins + kCoarseBins && s.direction_samples > 0; ++b) {
    seen += direction_bins_[static_cast<std::size_t>(b)];
    if (20 * seen >= 19 * s.direction_samples) {
      s.p95_direction_error_deg = std::min(
          b < kFineBins ? 0.01 * (b + 1) : 10.0 + (b - kFineBins + 1), s.max_direction_error_deg);
      break;
    }
  }
  s.rms_position_direction_error_deg =
      position_samples_ > 0
          ? std::sqrt(sum_sq_position_direction_ / static_cast<double>(position_samples_))
          : 0.0;
  return s;
}

}  // namespace craneassist::control
