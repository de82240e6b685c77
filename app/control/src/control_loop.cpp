#include "craneassist/control/control_loop.hpp"

#include <time.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

#include "craneassist/input/command_source.hpp"

namespace craneassist::control {
namespace {

double seconds(const timespec& t) {
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

timespec monotonic_now() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t;
}

void add_ns(timespec& t, long ns) {
  t.tv_nsec += ns;
  while (t.tv_nsec >= 1000000000L) {
    t.tv_nsec -= 1000000000L;
    ++t.tv_sec;
  }
}

// Sleeps until the absolute CLOCK_MONOTONIC time (through signals).
void sleep_until(const timespec& t) {
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &t, nullptr) == EINTR) {
  }
}

}  // namespace

const char* status_word(CycleStatus status) {
  switch (status) {
    case CycleStatus::kRunning:
      return "running";
    case CycleStatus::kStopping:
      return "stopping";
    case CycleStatus::kStopped:
      return "stopped";
  }
  return "unknown";
}

long run_cycles(double cycles, const char* what) {
  if (!(cycles >= 0.0 && cycles <= static_cast<double>(kMaxRunCycles))) {
    throw std::invalid_argument(std::string(what) + ": a run of " + std::to_string(cycles) +
                                " cycles is not possible (at most " +
                                std::to_string(kMaxRunCycles) + ")");
  }
  return static_cast<long>(cycles);
}

LoopSummary run_control_loop(CycleTask& task, valves::MachineInterface& machine,
                             const LoopOptions& options) {
  const double period = options.period_s;
  const long period_ns = std::lround(period * 1e9);
  const long settle_cycles =
      run_cycles(std::ceil(options.stop_settle_max_s / period), "the stop's settle time");

  valves::MachineState state;
  valves::ValveCommand command;
  LogRow row;
  LoopSummary summary;
  CycleTime time;

  machine.read(state);
  bool polytope = options.log != nullptr;
  for (const CycleObserver* o : options.observers) polytope = polytope || o->reads_polytope();
  task.set_polytope(polytope);
  task.start(state, machine.command_period_s());
  summary.realtime_result = apply_realtime_setup(options.realtime_setup);
  const timespec wall_start = monotonic_now();
  timespec next_tick = wall_start;
  long stop_requested_at = -1;  // cycle of the stop request
  const char* stop_cause = nullptr;
  bool frozen_once = false;
  double last_compute_s = 0.0;
  long k = 0;
  CycleStatus last_status = CycleStatus::kRunning;
  for (;; ++k) {
    if (stop_cause == nullptr && (k >= options.max_cycles || task.finished())) {
      // The end of the run: stop the machine, never leave it moving (unless it already is).
      if (k == 0 || !options.stop_at_end || last_status == CycleStatus::kStopped) break;
      stop_requested_at = k;
      stop_cause = "end of run";
      summary.end_stop = true;
    }
    const timespec woke = monotonic_now();
    time.k = k;
    time.t_s = options.t0_s + static_cast<double>(k) * period;
    if (options.realtime) summary.timing.start_latency.add(seconds(woke) - seconds(next_tick));
    time.now_s = options.realtime ? input::steady_now_s() : time.t_s;
    const valves::BackendStatus machine_status = machine.read(state);
    if (machine_status == valves::BackendStatus::kFault && !summary.machine_fault) {
      // A latched machine fault (CAN) ends the run: the machine is already safe (blocked); the
      // task stops its reference as for a quit.
      summary.machine_fault = true;
      if (stop_cause == nullptr) {
        stop_requested_at = k;
        stop_cause = "machine fault";
      }
    }
    if (stop_cause == nullptr && options.stop != nullptr &&
        options.stop->load(std::memory_order_relaxed)) {
      stop_requested_at = k;
      stop_cause = options.stop_cause;
    }
    const CycleStatus status = task.step(time, state, stop_cause, command, row);
    last_status = status;
    machine.write(command);
    row.loop_latency_max_s = summary.max_late_s();
    row.loop_compute_s = last_compute_s;
    row.loop_overruns = summary.timing.overruns;
    if (options.log != nullptr) options.log->push(row);
    const CycleRecord record{time,      state, command, row, status, task.controller_output(),
                             stop_cause};
    for (CycleObserver* o : options.observers) o->on_cycle(record);

    machine.advance(period);
    const double done_s = seconds(monotonic_now());
    last_compute_s = done_s - seconds(woke);
    summary.timing.compute.add(last_compute_s);
    if (stop_cause != nullptr && status == CycleStatus::kStopped) {
      ++k;
      break;
    }
    if (stop_cause != nullptr && k - stop_requested_at >= settle_cycles) {
      machine.safe_stop();  // not at rest in time: every valve to its safe state now
      summary.safe_stopped = true;
      ++k;
      break;
    }
    if (!frozen_once && options.freeze_at_s >= 0.0 && time.t_s >= options.freeze_at_s) {
      std::this_thread::sleep_for(std::chrono::duration<double>(options.freeze_for_s));
      next_tick = monotonic_now();
      frozen_once = true;
    }
    if (options.realtime) {
      add_ns(next_tick, period_ns);
      if (done_s > seconds(next_tick)) ++summary.timing.overruns;
      sleep_until(next_tick);
    }
  }
  undo_realtime_setup(summary.realtime_result);
  machine.read(state);
  for (CycleObserver* o : options.observers) o->on_finish(time, state);
  summary.cycles = k;
  summary.duration_s = static_cast<double>(k) * period;
  summary.stop_requested = stop_cause != nullptr && !summary.end_stop;
  summary.stop_cycles = stop_requested_at >= 0 ? k - stop_requested_at : 0;
  summary.wall_time_s = seconds(monotonic_now()) - seconds(wall_start);
  if (options.log != nullptr) summary.log_rows_dropped = options.log->close();
  return summary;
}

}  // namespace craneassist::control
