// The cycle task of every tip-velocity run (replay, live `sim`): a command input, the Controller
// and the log row. The input says what the operator commands this cycle; a replay plays its rows
// back, a live device goes through the input monitor. Because both feed the same task, a
// recorded session (the command the controller got, RecordingObserver) replays to the same log
// by construction.
#pragma once

#include <Eigen/Core>
#include <limits>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/control/controller.hpp"
#include "craneassist/control/log_row_builder.hpp"
#include "craneassist/input/command_source.hpp"
#include "craneassist/input/input_monitor.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/scaling/base_drive.hpp"

namespace craneassist::control {

// What the operator commands in one cycle.
struct TipCommand {
  // Tip velocity, crane frame; non-finite: no command (the controller's jerk-limited stop along
  // the current direction, then neutral valves).
  Eigen::Vector3d v_m_s = Eigen::Vector3d::Zero();
  const char* reason = "";  // why there is no command ("" when there is one); static
  bool deadman = false;
  // The drive stick (speed, curvature fractions in [-1, 1]; input::OperatorCommand::drive),
  // zero when the command does not pass.
  Eigen::Vector2d drive = Eigen::Vector2d::Zero();
  // The load a replay puts in the simulated crane's grapple (NaN: unchanged; ValveCommand).
  double simulated_load_kg = std::numeric_limits<double>::quiet_NaN();
};

class TipCommandInput {
 public:
  virtual ~TipCommandInput() = default;
  // The command of this cycle; tip_m is the measured tip (NaN when there is no valid
  // measurement). Non-blocking, allocation-free.
  virtual void next(const CycleTime& time, const Eigen::Vector3d& tip_m,
                    TipCommand& out) noexcept = 0;
  virtual const char* name() const noexcept = 0;  // LogRow::input_source
};

// A replay file's rows at machine time (a stop row gives no command, reason "replay stop row").
class ReplayInput final : public TipCommandInput {
 public:
  explicit ReplayInput(const input::Replay& replay) : cursor_(replay) {}
  void next(const CycleTime& time, const Eigen::Vector3d& tip_m, TipCommand& out) noexcept override;
  const char* name() const noexcept override { return "replay"; }

 private:
  input::ReplayCursor cursor_;
};

// An operator's live source behind the input monitor: the command passes only while the monitor
// enables it (docs/joystick.md#input-safety); otherwise the reason is the monitor's fault.
class MonitoredInput final : public TipCommandInput {
 public:
  MonitoredInput(input::CommandSource& source, const input::InputMonitorSettings& settings)
      : source_(source), monitor_(settings) {}
  void next(const CycleTime& time, const Eigen::Vector3d& tip_m, TipCommand& out) noexcept override;
  const char* name() const noexcept override { return source_.name(); }

  const input::InputMonitor& monitor() const noexcept { return monitor_; }
  const input::MonitorOutput& last() const noexcept { return mon_; }
  input::SourceState source_state() const noexcept { return source_state_; }

 private:
  input::CommandSource& source_;
  input::InputMonitor monitor_;
  input::OperatorCommand sample_;
  input::MonitorOutput mon_;
  input::SourceState source_state_ = input::SourceState::kNoData;
};

class TipCommandTask final : public CycleTask {
 public:
  TipCommandTask(const config::CraneConfig& config, const ControllerOptions& options,
                 TipCommandInput& input);

  void start(const valves::MachineState& state, double valve_command_period_s) override;
  CycleStatus step(const CycleTime& time, const valves::MachineState& state, const char* stop_cause,
                   valves::ValveCommand& command, LogRow& row) noexcept override;
  const ControllerOutput* controller_output() const noexcept override { return &out_; }

  double period_s() const noexcept { return controller_.period_s(); }
  // The crane stands on this wheeled base (kept by reference; nullptr: a fixed base): each cycle
  // the drive stick becomes the base's flow-bounded velocity command (scaling::flow_bounded_drive,
  // against the drive pump's Q_max), written with the spools (ValveCommand::drive_*); zero
  // while the command does not pass or the loop stops.
  void set_base(const dynamics::MobileBaseModel* base) noexcept { base_ = base; }
  const scaling::BaseDriveOutput& drive() const noexcept { return drive_; }
  // The measured tip of the last step (zero without a valid measurement).
  const Eigen::Vector3d& tip() const noexcept { return builder_.tip(); }
  const Eigen::Vector3d& tip_velocity() const noexcept { return builder_.tip_velocity(); }

 private:
  TipCommandInput& input_;
  Controller controller_;
  LogRowBuilder builder_;
  ControllerOutput out_;
  TipCommand command_;
  const dynamics::MobileBaseModel* base_ = nullptr;
  scaling::BaseDriveOutput drive_;
};

}  // namespace craneassist::control
