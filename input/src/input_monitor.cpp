#include "craneassist/input/input_monitor.hpp"

#include <cmath>

namespace craneassist::input {

const char* to_string(InputFault fault) {
  switch (fault) {
    case InputFault::kNone:
      return "";
    case InputFault::kDisconnected:
      return "device disconnected";
    case InputFault::kNoData:
      return "no input yet";
    case InputFault::kStale:
      return "input stale";
    case InputFault::kNotFinite:
      return "command not finite";
    case InputFault::kOutOfRange:
      return "command out of range";
    case InputFault::kDeadmanReleased:
      return "deadman released";
    case InputFault::kNotArmed:
      return "re-arm: release and press the deadman";
    case InputFault::kStopLatched:
      return "stop latched";
    case InputFault::kArming:
      return "arming: keep the deadman held";
  }
  return "unknown";
}

void InputMonitor::update(SourceState state, const OperatorCommand& sample, double now_s,
                          MonitorOutput& out) noexcept {
  // Device events (edges of the disconnected state).
  const bool gone = state == SourceState::kDisconnected;
  if (gone && !disconnected_ && connected_seen_) ++disconnects_;
  if (!gone && disconnected_ && connected_seen_) ++reconnects_;
  disconnected_ = gone;
  connected_seen_ = connected_seen_ || !gone;
  if (state == SourceState::kOk) has_sample_ = true;

  out.deadman = state == SourceState::kOk && sample.deadman;
  out.input_age_s = has_sample_ ? now_s - sample.stamp_s : 0.0;

  InputFault fault = InputFault::kNone;
  if (gone) {
    fault = InputFault::kDisconnected;
  } else if (state != SourceState::kOk) {
    fault = InputFault::kNoData;
  } else if (!std::isfinite(sample.stamp_s) || !(out.input_age_s <= settings_.stale_timeout_s)) {
    fault = InputFault::kStale;
  } else if (!sample.v_m_s.allFinite() || !sample.drive.allFinite()) {
    fault = InputFault::kNotFinite;
  } else if (sample.v_m_s.cwiseAbs().maxCoeff() > settings_.max_speed_m_s ||
             sample.drive.cwiseAbs().maxCoeff() > 1.0) {
    fault = InputFault::kOutOfRange;
  } else if (!sample.deadman) {
    fault = InputFault::kDeadmanReleased;
  }

  if (fault == InputFault::kDeadmanReleased) {
    armed_ = false;
    released_seen_ = true;  // a valid, fresh release: the next press arms
  } else if (fault != InputFault::kNone) {
    armed_ = false;
    released_seen_ = false;  // after the fault is gone the deadman must be released again
  } else {
    if (!armed_) {
      if (released_seen_) {
        armed_ = true;
        armed_at_s_ = now_s;
      } else {
        fault = InputFault::kNotArmed;
      }
    }
    // Armed and pressed, no fault: the stop latch, then the continuous hold. (Negated
    // comparisons: a clock that is not finite keeps the command stopped. The tolerance keeps a
    // time that is a whole number of cycles from missing its cycle by rounding.)
    constexpr double kTolerance_s = 1e-9;
    if (armed_) {
      if (ever_enabled_ && !enabled_ &&
          !(now_s - stopped_at_s_ + kTolerance_s >= settings_.stop_latch_s)) {
        fault = InputFault::kStopLatched;
      } else if (!(now_s - armed_at_s_ + kTolerance_s >= settings_.deadman_hold_s)) {
        fault = InputFault::kArming;
      }
    }
  }

  out.fault = fault;
  out.enabled = armed_ && fault == InputFault::kNone;
  if (enabled_ && !out.enabled) stopped_at_s_ = now_s;
  enabled_ = out.enabled;
  ever_enabled_ = ever_enabled_ || out.enabled;
  if (out.enabled) {
    out.v_m_s = sample.v_m_s;
    out.drive = sample.drive;
  } else {
    out.v_m_s.setZero();
    out.drive.setZero();
  }
}

}  // namespace craneassist::input
