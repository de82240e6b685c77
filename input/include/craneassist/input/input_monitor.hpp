// The input monitor: between a CommandSource and the controller, it decides each cycle whether
// the operator's command may move the machine.
//
// Faults (checked in this order): the device disconnected, nothing received yet, no fresh sample
// within stale_timeout, a non-finite command, a component above max_speed, the deadman released.
// Under any fault the monitor's command is zero and not enabled, and stop_reason says why; the
// live loop then gives the controller a non-finite command: its jerk-limited stop along the
// current direction, then neutral valves (docs/joystick.md#input-safety). Motion resumes only after
// the fault is gone and the deadman has been released and pressed again (re-arm); a deadman held
// since start-up does not arm either.
//
// Two timing rules make a released deadman always end in a stop, also when it chatters: the
// command passes only once the deadman has been held continuously (fresh, valid samples, no
// release) for deadman_hold since the press that armed it, and once the command has stopped
// passing (a release or any fault) it stays stopped at least stop_latch, long enough for the
// controller's stop to complete. A deadman that chatters never stays pressed long enough.
//
// update() allocates nothing, throws nothing, and its strings are static.
#pragma once

#include <Eigen/Core>

#include "craneassist/input/command_source.hpp"

namespace craneassist::input {

struct InputMonitorSettings {
  double stale_timeout_s = 0.1;  // no fresh sample for longer than this: stop
  double max_speed_m_s = 2.0;    // a command component above this is rejected
  // The deadman must be held continuously this long after the press that (re-)arms before the
  // command passes: a chattering or bouncing deadman never arms.
  double deadman_hold_s = 0.3;
  // Once the command has stopped passing (deadman released, any fault), it stays stopped at
  // least this long: the controller's jerk-limited stop runs to its end (the K70M stops from its
  // top speed of 0.5 m/s in about 0.8 s).
  double stop_latch_s = 1.0;
};

enum class InputFault {
  kNone,
  kDisconnected,
  kNoData,
  kStale,
  kNotFinite,
  kOutOfRange,
  kDeadmanReleased,
  kNotArmed,     // no fault, but the deadman must be released and pressed to (re-)arm
  kStopLatched,  // armed, but the command stopped less than stop_latch ago
  kArming,       // armed, but the deadman held for less than deadman_hold
};
// "device disconnected", "no input yet", "input stale", "command not finite", "command out of
// range", "deadman released", "re-arm: release and press the deadman", "stop latched",
// "arming: keep the deadman held"; "" for kNone.
const char* to_string(InputFault fault);

struct MonitorOutput {
  Eigen::Vector3d v_m_s = Eigen::Vector3d::Zero();  // what the controller gets
  Eigen::Vector2d drive = Eigen::Vector2d::Zero();  // the drive stick, passed with v_m_s
  bool enabled = false;                             // the operator's command passes
  InputFault fault = InputFault::kNoData;
  bool deadman = false;      // as the source reports it (false when there is no sample)
  double input_age_s = 0.0;  // now - stamp of the latest sample (0 before any)
};

class InputMonitor {
 public:
  explicit InputMonitor(const InputMonitorSettings& settings) noexcept : settings_(settings) {}

  // One cycle: what the source's poll() returned and the loop's clock (same clock as the stamps).
  void update(SourceState state, const OperatorCommand& sample, double now_s,
              MonitorOutput& out) noexcept;

  bool armed() const noexcept { return armed_; }
  // Counters of device events, for logs and status.
  int disconnects() const noexcept { return disconnects_; }
  int reconnects() const noexcept { return reconnects_; }
  const InputMonitorSettings& settings() const noexcept { return settings_; }

 private:
  InputMonitorSettings settings_;
  bool armed_ = false;
  bool released_seen_ = false;  // a fresh, valid sample with the deadman released since the fault
  double armed_at_s_ = 0.0;     // the press that armed
  bool enabled_ = false;        // the command passed in the last cycle
  bool ever_enabled_ = false;
  double stopped_at_s_ = 0.0;  // the command stopped passing (when ever_enabled_)
  bool disconnected_ = false;
  bool connected_seen_ = false;  // disconnects count only after a connection
  bool has_sample_ = false;
  int disconnects_ = 0;
  int reconnects_ = 0;
};

}  // namespace craneassist::input
