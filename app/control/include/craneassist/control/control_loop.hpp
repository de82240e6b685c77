// The one fixed-rate control loop of craneassist. Every run of the product goes through it:
// replay, live `sim`, trajectory execution, the 2R experiment and the valve calibration. Two
// studies of the papers run their own loops on their own simulators and do not: `follow` (paper
// 003's base and crane, research/studies/mobile_follow) and `ptp --simulate` (paper 001's MHSB arm,
// research/studies/ptp_simulation on sim_backend's MHSB simulator). Each cycle:
//
//   read the machine -> the cycle task (command source + controller) -> write the valves
//   -> the CSV log and the observers -> let one period pass -> pace (real time, or machine time)
//
// What differs between runs is the task (what turns a measurement into a valve command) and the
// observers (statistics, telemetry, recording); the loop, its clock, its pacing and its stopping
// are the same for all of them.
//
// Stopping is uniform. A stop request (the caller's stop flag: a signal or the keyboard's q; or
// a machine fault, BackendStatus::kFault) is handed to the task, which brings the machine to
// rest (the controller's jerk-limited stop, then neutral valves); the loop keeps cycling until
// the task reports kStopped, at most stop_settle_max_s (then it calls the machine's safe_stop()),
// and ends. A run also ends after max_cycles, or when its task has finished (a calibration sweep).
//
// The loop allocates nothing and throws nothing once running: the task's step() and the
// observers' on_cycle() are noexcept and allocation-free (their contract), the log is a ring.
#pragma once

#include <atomic>
#include <vector>

#include "craneassist/control/csv_log.hpp"
#include "craneassist/control/cycle_timing.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::control {

struct ControllerOutput;

// Where the machine is in a stop (the tip controller's status; every task reports one).
enum class CycleStatus {
  kRunning,   // following its command
  kStopping,  // bringing the machine to rest
  kStopped,   // at rest, every valve neutral
};
// "running", "stopping", "stopped" (LogRow::status).
const char* status_word(CycleStatus status);

// The loop's clocks for one cycle.
struct CycleTime {
  long k = 0;          // cycle number, from 0
  double t_s = 0.0;    // machine time: t0 + k * period
  double now_s = 0.0;  // the input clock: steady_clock seconds when paced, else t_s
};

// What runs between read and write: a command source and the controller that follows it.
class CycleTask {
 public:
  virtual ~CycleTask() = default;
  // Before the first cycle, with the first measurement and how often a written command reaches
  // the valves (MachineInterface::command_period_s). May allocate and throw.
  virtual void start(const valves::MachineState& state, double valve_command_period_s) = 0;
  // One period: the valve command for the measured state, and every field of the log row.
  // stop_cause: nullptr, or why the loop asks for a stop (a static string, e.g. "operator quit",
  // "machine fault"); from then on the task brings the machine to rest.
  virtual CycleStatus step(const CycleTime& time, const valves::MachineState& state,
                           const char* stop_cause, valves::ValveCommand& command,
                           LogRow& row) noexcept = 0;
  // The tip controller's output of the last step(), for statistics; nullptr for tasks without
  // one (trajectory execution, calibration).
  virtual const ControllerOutput* controller_output() const noexcept { return nullptr; }
  // True once the task has done its work, when that is not a fixed number of cycles (a valve
  // calibration sweep on a machine: it moves the section between levels for as long as that
  // takes). The loop then ends the run as at LoopOptions::max_cycles. Tasks that run for a given
  // time never finish.
  virtual bool finished() const noexcept { return false; }
  // Before start(): whether the run's log or an observer reads the flow manipulability
  // polytope's figures of the row (the controller computes them only then; PolytopeProbe).
  // May allocate.
  virtual void set_polytope(bool on) { (void)on; }
};

// One finished cycle, as the observers see it (after the valves are written).
struct CycleRecord {
  const CycleTime& time;
  const valves::MachineState& state;
  const valves::ValveCommand& command;
  const LogRow& row;
  CycleStatus status;
  const ControllerOutput* controller;  // CycleTask::controller_output()
  // The loop's stop in progress ("operator quit", "machine fault", "end of run"); nullptr while
  // the run goes on.
  const char* stop_cause = nullptr;
};

// Something that watches the loop cycle by cycle (statistics, DDS telemetry, recording, a test
// probe). Called on the loop's thread once per period; it must return at once: no lock, no
// allocation, no I/O (copy into a preallocated ring).
class CycleObserver {
 public:
  virtual ~CycleObserver() = default;
  virtual void on_cycle(const CycleRecord& cycle) noexcept = 0;
  // Whether it reads the polytope's figures of the row (avail_speed_m_s, polytope_*): the
  // controller computes them only for a run with a log or an observer that does. Unless it
  // says otherwise, an observer does.
  virtual bool reads_polytope() const noexcept { return true; }
  // After the last cycle, with the machine read once more (its integrated energy).
  virtual void on_finish(const CycleTime& last, const valves::MachineState& state) {
    (void)last;
    (void)state;
  }
};

struct LoopOptions {
  double period_s = 0.01;
  double t0_s = 0.0;  // machine time of cycle 0
  // The run's length in cycles (or less: CycleTask::finished()); a stop request may end it
  // earlier. When the run reaches it with
  // the machine not stopped, the loop stops it as for a stop request (cause "end of run"): a
  // jerk-limited stop, then the task's neutral valves, or safe_stop() after stop_settle_max_s.
  // Build it with run_cycles().
  long max_cycles = 0;
  // false: the run just ends at max_cycles (a segment of a study on the simulator that the next
  // segment continues, e.g. one level of a valve calibration sweep).
  bool stop_at_end = true;
  // true: paced at the period on CLOCK_MONOTONIC (absolute clock_nanosleep, as cyclictest), the
  // input clock is steady_clock; false: as fast as possible, the input clock is machine time.
  bool realtime = false;
  // Memory lock, SCHED_FIFO priority and core of the loop thread for the run (cycle_timing.hpp);
  // applied before the first cycle and undone after the last.
  RealtimeSetup realtime_setup;
  const std::atomic<bool>* stop = nullptr;  // set by a signal handler or the keyboard's q
  const char* stop_cause = "operator quit";
  // After a stop request, run until the task reports kStopped, at most this long.
  double stop_settle_max_s = 5.0;
  std::vector<CycleObserver*> observers;
  CsvLog* log = nullptr;
  // Test hook (the CAN watchdog tests): at this machine time the loop stops for freeze_for_s
  // without reading or writing, as a hung control thread would. Negative: never.
  double freeze_at_s = -1.0;
  double freeze_for_s = 0.0;
};

struct LoopSummary {
  long cycles = 0;
  double duration_s = 0.0;         // machine time
  double wall_time_s = 0.0;        // computer time
  RealtimeResult realtime_result;  // what the system granted of LoopOptions::realtime_setup
  CycleTiming timing;              // start latency (paced runs), compute time, overruns
  // Paced runs: the latest a cycle started after its tick.
  double max_late_s() const noexcept { return timing.start_latency.max_s(); }
  // The machine reported a fault (BackendStatus::kFault, e.g. a latched CAN fault): the loop
  // stopped as for a stop request (stop reason "machine fault").
  bool machine_fault = false;
  bool stop_requested = false;  // by the stop flag or a fault
  bool end_stop = false;        // the run reached max_cycles and the loop stopped the machine
  long stop_cycles = 0;         // cycles from the stop (request or end of run) to the run's end
  // The task did not bring the machine to rest within stop_settle_max_s of the stop request:
  // the loop called MachineInterface::safe_stop().
  bool safe_stopped = false;
  std::size_t log_rows_dropped = 0;
};

// The most cycles a run may have (about 317 years at 100 Hz): a bound that keeps every count in
// range; the files a run reads bound their times far lower (docs/safety.md).
inline constexpr long kMaxRunCycles = 1'000'000'000'000;

// `cycles` (a count computed in floating point, e.g. from a duration and a period) as a run
// length. Throws std::invalid_argument naming `what` when it is not finite, negative or above
// kMaxRunCycles (before any conversion: no undefined behaviour on 1e30 or NaN).
long run_cycles(double cycles, const char* what);

// Runs the task on the machine: task.start() with the first measurement, then the cycles.
// Closes the log at the end.
LoopSummary run_control_loop(CycleTask& task, valves::MachineInterface& machine,
                             const LoopOptions& options);

}  // namespace craneassist::control
