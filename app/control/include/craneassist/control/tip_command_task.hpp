// The cycle task of every tip-velocity run (replay, live `sim`): a command input, the Controller
// and the log row. The input says what the operator commands this cycle; a replay plays its rows
// back, a live device goes through the input monitor. Because both feed the same task, a
// recorded session (the command the controller got, RecordingObserver) replays to the same log
// by construction.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/control/controller.hpp"
#include "craneassist/control/log_row_builder.hpp"
#include "craneassist/control/run_statistics.hpp"
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

// What an input sees of the machine in one cycle (NaN where there is no valid measurement).
struct InputMeasurement {
  Eigen::Vector3d tip_m = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d tip_v_m_s = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  double swing_rad = std::numeric_limits<double>::quiet_NaN();  // MachineState::swing_rad
};

class TipCommandInput {
 public:
  virtual ~TipCommandInput() = default;
  // The command of this cycle for the machine as measured. Non-blocking, allocation-free.
  virtual void next(const CycleTime& time, const InputMeasurement& measured,
                    TipCommand& out) noexcept = 0;
  virtual const char* name() const noexcept = 0;  // LogRow::input_source
  // True once the input has nothing more to give (TipCommandTask::finished).
  virtual bool finished(long next_cycle) const noexcept {
    (void)next_cycle;
    return false;
  }
};

// How a replay's wait rows wait (docs/replay-format.md#waits): the run holds a wait row's
// command until the grapple's swing has stayed within swing_rad for window_s (and, when the
// row's command is zero, the measured tip slower than rest_speed_m_s), at most timeout_s; every
// later row then comes that much later. Without a swing measurement, the tip alone.
struct WaitSettings {
  double swing_rad = 2.0 * M_PI / 180.0;
  double window_s = 2.0;  // about one swing period: a swing's magnitude passes zero twice in one
  double rest_speed_m_s = 0.005;
  double timeout_s = 30.0;
};

// A replay file's rows at machine time (a stop row gives no command, reason "replay stop row"),
// with its waits: the replay's clock stands still while a wait row waits.
class ReplayInput final : public TipCommandInput {
 public:
  // period_s: the loop's; end_cycles: the run's length without waits (run_cycles of the last
  // row's time and the settle time): each cycle waited adds one.
  ReplayInput(const input::Replay& replay, const WaitSettings& waits = {}, double period_s = 0.01,
              long end_cycles = 0);
  void next(const CycleTime& time, const InputMeasurement& measured,
            TipCommand& out) noexcept override;
  const char* name() const noexcept override { return "replay"; }
  bool finished(long next_cycle) const noexcept override {
    return waited_cycles_ > 0 && next_cycle >= end_cycles_ + waited_cycles_;
  }
  const WaitSummary& waits() const noexcept { return summary_; }
  // The replay's own time at machine time t_s: t_s less the time waited so far.
  double replay_time(double t_s) const noexcept {
    return t_s - static_cast<double>(waited_cycles_) * period_s_;
  }

 private:
  // Advances the wait in progress (or starts the one due at replay time tau); true while it
  // holds this cycle.
  bool hold(const CycleTime& time, double tau, const InputMeasurement& measured) noexcept;

  const input::Replay& replay_;
  input::ReplayCursor cursor_;
  WaitSettings settings_;
  double period_s_;
  long end_cycles_;
  std::size_t next_row_ = 0;  // the rows before it have had their wait
  long waited_cycles_ = 0;
  bool waiting_ = false;
  double wait_start_s_ = 0.0, unsettled_s_ = 0.0;
  WaitSummary summary_;
};

// An operator's live source behind the input monitor: the command passes only while the monitor
// enables it (docs/joystick.md#input-safety); otherwise the reason is the monitor's fault.
class MonitoredInput final : public TipCommandInput {
 public:
  MonitoredInput(input::CommandSource& source, const input::InputMonitorSettings& settings)
      : source_(source), monitor_(settings) {}
  void next(const CycleTime& time, const InputMeasurement& measured,
            TipCommand& out) noexcept override;
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
  void set_polytope(bool on) override { controller_.set_polytope(on); }
  bool finished() const noexcept override { return input_.finished(next_cycle_); }

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
  long next_cycle_ = 0;
};

}  // namespace craneassist::control
