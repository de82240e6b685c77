#include "craneassist/app/control_loop.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "craneassist/input/command_source.hpp"

namespace craneassist::app {

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

LoopSummary run_control_loop(CycleTask& task, valves::MachineInterface& machine,
                             const LoopOptions& options) {
  using Clock = std::chrono::steady_clock;
  const double period = options.period_s;
  const auto tick =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period));
  const long settle_cycles = static_cast<long>(std::ceil(options.stop_settle_max_s / period));

  valves::MachineState state;
  valves::ValveCommand command;
  LogRow row;
  LoopSummary summary;
  CycleTime time;

  machine.read(state);
  task.start(state, machine.command_period_s());
  const auto wall_start = Clock::now();
  auto next_tick = wall_start;
  long stop_requested_at = -1;  // cycle of the stop request
  const char* stop_cause = nullptr;
  bool frozen_once = false;
  long k = 0;
  for (; k < options.max_cycles; ++k) {
    time.k = k;
    time.t_s = options.t0_s + static_cast<double>(k) * period;
    if (options.realtime) {
      summary.max_late_s = std::max(
          summary.max_late_s, std::chrono::duration<double>(Clock::now() - next_tick).count());
    }
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
    machine.write(command);
    if (options.log != nullptr) options.log->push(row);
    const CycleRecord record{time, state, command, row, status, task.controller_output()};
    for (CycleObserver* o : options.observers) o->on_cycle(record);

    machine.advance(period);
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
      next_tick = Clock::now();
      frozen_once = true;
    }
    if (options.realtime) {
      next_tick += tick;
      std::this_thread::sleep_until(next_tick);
    }
  }
  machine.read(state);
  for (CycleObserver* o : options.observers) o->on_finish(time, state);
  summary.cycles = k;
  summary.duration_s = static_cast<double>(k) * period;
  summary.stop_requested = stop_cause != nullptr;
  summary.wall_time_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
  if (options.log != nullptr) summary.log_rows_dropped = options.log->close();
  return summary;
}

}  // namespace craneassist::app
