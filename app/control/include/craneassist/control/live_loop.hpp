// A live run (`craneassist sim`): an operator's CommandSource behind the input monitor as the
// command of the tip controller, through the one control loop (control_loop.hpp) paced at real
// time, with the CSV log and the cycle observers (telemetry). Optionally it records the command
// the controller got, in the replay format, so `craneassist replay` reproduces the session.
//
// The loop thread allocates nothing per cycle, never blocks on another thread (the status board
// is published with try_lock) and throws nothing once running.
#pragma once

#include <atomic>
#include <mutex>
#include <vector>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/control/controller.hpp"
#include "craneassist/control/csv_log.hpp"
#include "craneassist/control/run_statistics.hpp"
#include "craneassist/dynamics/mobile_base.hpp"
#include "craneassist/input/command_source.hpp"
#include "craneassist/input/input_monitor.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::control {

// The latest state of the loop for a user interface on another thread (the status line, the
// device event messages). The loop publishes with try_lock (skips a cycle rather than wait).
struct LiveStatus {
  double t = 0.0;  // machine time
  Eigen::Vector3d tip = Eigen::Vector3d::Zero(), tip_v = Eigen::Vector3d::Zero();
  Eigen::Vector3d cmd = Eigen::Vector3d::Zero();  // what the controller got
  const char* status = "stopped";
  const char* stop_reason = "";
  input::InputFault fault = input::InputFault::kNoData;
  input::SourceState source = input::SourceState::kNoData;
  bool deadman = false;
  double input_age_s = 0.0;
  int disconnects = 0, reconnects = 0;
  valves::BaseMeasurement base;  // the wheeled base (sim --base); present false without one
};

class LiveStatusBoard {
 public:
  void publish(const LiveStatus& s) noexcept {
    if (mutex_.try_lock()) {
      status_ = s;
      mutex_.unlock();
    }
  }
  LiveStatus read() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return status_;
  }

 private:
  mutable std::mutex mutex_;
  LiveStatus status_;
};

struct LiveOptions {
  ControllerOptions controller;
  input::InputMonitorSettings monitor;
  // The crane stands on this wheeled base, driven by the operator's drive stick
  // (TipCommandTask::set_base; the machine must take the drive command: MobileCraneBackend).
  // nullptr: a fixed base. Kept by reference.
  const dynamics::MobileBaseModel* base = nullptr;
  // true: paced at the control rate, the monitor's clock is steady_clock (device sources);
  // false: as fast as possible, the clock is machine time (scripted sources and tests only).
  bool realtime = true;
  // Memory lock, SCHED_FIFO priority and core of the loop thread (realtime runs).
  RealtimeSetup realtime_setup;
  double duration_s = 0.0;                  // machine time to run; 0: until *stop is set
  const std::atomic<bool>* stop = nullptr;  // set by a signal handler or the keyboard's q
  // After a stop request (or a machine fault), keep running with a non-finite command (the
  // controller's stop, then neutral valves) until the machine is at rest with neutral valves, at
  // most this long, so the crane is not left moving.
  double stop_settle_max_s = 5.0;
  std::vector<CycleObserver*> observers;  // called each cycle on the loop thread
  LiveStatusBoard* status_board = nullptr;
  // Recording: the command the controller got, rows where it changes (and a last row at the
  // final cycle), machine time. Preallocated; rows beyond the capacity are dropped and counted.
  std::vector<input::ReplayRow>* record = nullptr;
  std::size_t record_capacity = 1 << 19;
};

struct LiveSummary {
  LoadSummary load;              // the crane scale and the load moment (docs/loads.md)
  StopSummary stop;              // how the stops ended (docs/safety.md)
  SwingSummary swing;            // the hanging grapple's swing (docs/sway.md)
  double peak_spool_step = 0.0;  // largest spool command change per cycle
  long cycles = 0;
  double duration_s = 0.0;   // machine time
  double wall_time_s = 0.0;  // computer time
  double max_late_s = 0.0;   // realtime: the latest a cycle started after its tick
  double peak_tip_speed_m_s = 0.0;
  double tip_path_m = 0.0;
  long enabled_cycles = 0;  // cycles the operator's command passed the monitor
  int disconnects = 0, reconnects = 0;
  std::size_t log_rows_dropped = 0;
  std::size_t record_rows_dropped = 0;
  // The machine reported a fault (BackendStatus::kFault, e.g. a latched CAN fault): the loop
  // stopped as for a stop request (stop reason "machine fault").
  bool machine_fault = false;
  // How the run ended: its duration reached with the crane moving (end_stop) or a stop request;
  // the loop's stop took stop_cycles cycles (jerk-limited, then neutral valves).
  bool end_stop = false;
  long stop_cycles = 0;
  RealtimeResult realtime_result;  // what the system granted of LiveOptions::realtime_setup
  CycleTiming timing;              // start latency, compute time, overruns (cycle_timing.hpp)
};

// The clock of device sources' stamps (input/command_source.hpp).
using input::steady_now_s;

LiveSummary run_live(const config::CraneConfig& config, input::CommandSource& source,
                     valves::MachineInterface& machine, const LiveOptions& options, CsvLog* log);

}  // namespace craneassist::control
