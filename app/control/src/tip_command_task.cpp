#include "craneassist/control/tip_command_task.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace craneassist::control {
namespace {

const Eigen::Vector3d kNoValue =
    Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());

}  // namespace

ReplayInput::ReplayInput(const input::Replay& replay, const WaitSettings& waits, double period_s,
                         long end_cycles)
    : replay_(replay),
      cursor_(replay),
      settings_(waits),
      period_s_(period_s),
      end_cycles_(end_cycles) {}

bool ReplayInput::hold(const CycleTime& time, double tau,
                       const InputMeasurement& measured) noexcept {
  const auto& rows = replay_.rows();
  if (!waiting_) {
    // The next wait row the replay has reached (rows passed without waiting have none).
    while (next_row_ < rows.size() && rows[next_row_].t_s <= tau && !rows[next_row_].wait) {
      ++next_row_;
    }
    if (next_row_ == rows.size() || rows[next_row_].t_s > tau) return false;
    waiting_ = true;
    wait_start_s_ = unsettled_s_ = time.t_s;
    ++summary_.waits;
  }
  const input::ReplayRow& row = rows[next_row_];
  const double swing = std::abs(measured.swing_rad);
  const double speed = measured.tip_v_m_s.norm();
  const bool swing_measured = std::isfinite(swing);
  // Still settling: the swing beyond the bound, or the tip moving where the stick is released
  // (without any measurement nothing can be seen to settle).
  const bool unsettled = (swing_measured && swing > settings_.swing_rad) ||
                         (row.v_m_s.isZero(0.0) && !(speed <= settings_.rest_speed_m_s)) ||
                         (!swing_measured && !std::isfinite(speed));
  if (unsettled) unsettled_s_ = time.t_s;
  const double waited_s = time.t_s - wait_start_s_;
  if (swing_measured && waited_s >= 1.0) {
    const double deg = swing * 180.0 / M_PI;
    summary_.residual_swing_deg =
        std::isnan(summary_.residual_swing_deg) ? deg : std::max(summary_.residual_swing_deg, deg);
  }
  const bool settled = time.t_s - unsettled_s_ >= settings_.window_s;
  const bool timeout = waited_s >= settings_.timeout_s;
  if (!settled && !timeout) return true;
  waiting_ = false;
  ++next_row_;
  summary_.total_s += waited_s;
  summary_.longest_s = std::max(summary_.longest_s, waited_s);
  if (!settled) ++summary_.timed_out;
  return false;
}

void ReplayInput::next(const CycleTime& time, const InputMeasurement& measured,
                       TipCommand& out) noexcept {
  double tau = replay_time(time.t_s);
  if (hold(time, tau, measured)) {
    // The replay's clock stands still: the wait row's command (and load) this cycle again.
    ++waited_cycles_;
    tau = replay_.rows()[next_row_].t_s;
  }
  out.v_m_s = cursor_.command_at(tau);
  const bool finite = out.v_m_s.allFinite();
  out.reason = finite ? "" : "replay stop row";
  out.deadman = finite;
  out.drive.setZero();
  out.simulated_load_kg = cursor_.load_at(tau);
}

void MonitoredInput::next(const CycleTime& time, const InputMeasurement& measured,
                          TipCommand& out) noexcept {
  source_.begin_cycle(time.now_s, measured.tip_m);
  source_state_ = source_.poll(sample_);
  monitor_.update(source_state_, sample_, time.now_s, mon_);
  out.v_m_s = mon_.enabled ? mon_.v_m_s : kNoValue;
  out.reason = input::to_string(mon_.fault);
  out.deadman = mon_.deadman;
  out.drive = mon_.enabled ? mon_.drive : Eigen::Vector2d::Zero();
}

TipCommandTask::TipCommandTask(const config::CraneConfig& config, const ControllerOptions& options,
                               TipCommandInput& input)
    : input_(input), controller_(config, options), builder_(config.model) {}

void TipCommandTask::start(const valves::MachineState& state, double valve_command_period_s) {
  controller_.set_valve_command_period(valve_command_period_s);
  controller_.reset(state);
}

CycleStatus TipCommandTask::step(const CycleTime& time, const valves::MachineState& state,
                                 const char* stop_cause, valves::ValveCommand& command,
                                 LogRow& row) noexcept {
  builder_.measure(state);
  next_cycle_ = time.k + 1;
  InputMeasurement measured;
  if (state.valid) {
    measured.tip_m = builder_.tip();
    measured.tip_v_m_s = builder_.tip_velocity();
    measured.swing_rad = state.swing_rad;
  }
  input_.next(time, measured, command_);
  // A stop request overrides the operator: the controller gets no command.
  const Eigen::Vector3d& v = stop_cause != nullptr ? kNoValue : command_.v_m_s;
  const CycleStatus status = controller_.update(state, v, out_);
  // The controller stops as for a stale input; the log says it was asked to.
  if (stop_cause != nullptr && out_.limit == scaling::ActiveLimit::kStaleInput) {
    out_.limit = scaling::ActiveLimit::kStopRequest;
  }
  command.spool = out_.valves.spool;
  if (base_ != nullptr && stop_cause == nullptr && v.allFinite()) {
    scaling::flow_bounded_drive(*base_, command_.drive[0], command_.drive[1],
                                base_->pump_max_flow_m3_s, drive_);
  } else {
    drive_ = scaling::BaseDriveOutput{};
  }
  command.drive_v_m_s = drive_.v_m_s;
  command.drive_omega_rad_s = drive_.omega_rad_s;
  command.simulated_load_kg = command_.simulated_load_kg;

  builder_.fill(row, time.t_s, v, out_, state);
  row.status = status_word(status);
  const char* reason = stop_cause != nullptr ? stop_cause : command_.reason;
  if (v.allFinite() && status != CycleStatus::kRunning) {
    reason = out_.limit == scaling::ActiveLimit::kDynamicsFailed ? "dynamics failed"
                                                                 : "measurement invalid";
  }
  row.stop_reason = reason;
  row.deadman = command_.deadman;
  row.input_source = input_.name();
  row.base_command = {command.drive_v_m_s, command.drive_omega_rad_s};
  return status;
}

}  // namespace craneassist::control
