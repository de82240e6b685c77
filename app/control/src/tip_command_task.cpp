#include "craneassist/control/tip_command_task.hpp"

#include <limits>

namespace craneassist::control {
namespace {

const Eigen::Vector3d kNoValue =
    Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());

}  // namespace

void ReplayInput::next(const CycleTime& time, const Eigen::Vector3d&, TipCommand& out) noexcept {
  out.v_m_s = cursor_.command_at(time.t_s);
  const bool finite = out.v_m_s.allFinite();
  out.reason = finite ? "" : "replay stop row";
  out.deadman = finite;
  out.drive.setZero();
  out.simulated_load_kg = cursor_.load_at(time.t_s);
}

void MonitoredInput::next(const CycleTime& time, const Eigen::Vector3d& tip_m,
                          TipCommand& out) noexcept {
  source_.begin_cycle(time.now_s, tip_m);
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
  input_.next(time, state.valid ? builder_.tip() : kNoValue, command_);
  // A stop request overrides the operator: the controller gets no command.
  const Eigen::Vector3d& v = stop_cause != nullptr ? kNoValue : command_.v_m_s;
  const CycleStatus status = controller_.update(state, v, out_);
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
