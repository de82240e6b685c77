#include "craneassist/control/replay_runner.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/control/tip_command_task.hpp"
#include "craneassist/dynamics/pendulum.hpp"

namespace craneassist::control {

WaitSettings wait_settings(const config::CraneConfig& config, double swing_rad) {
  WaitSettings w;
  w.swing_rad = swing_rad;
  w.rest_speed_m_s = config.control.rest_speed_m_s;
  const auto& model = config.model;
  const double slowest = std::max(dynamics::grapple_pendulum(model, 0.0).period_s(),
                                  dynamics::grapple_pendulum(model, 1e5).period_s());
  w.window_s = std::isfinite(slowest) ? slowest : 0.5;
  return w;
}

RunSummary run_replay(const config::CraneConfig& config, const input::Replay& replay,
                      valves::MachineInterface& machine, const RunOptions& options, CsvLog* log) {
  const double period = 1.0 / config.control.rate_hz;
  const long end_cycles =
      run_cycles(std::ceil((replay.end_time_s() + options.settle_s) / period - 1e-9) + 1.0,
                 "the replay and its settle time");
  long wait_rows = 0;
  for (const auto& row : replay.rows()) wait_rows += row.wait ? 1 : 0;
  ReplayInput input(replay, options.waits, period, end_cycles);
  TipCommandTask task(config, options.controller, input);
  RunStatistics statistics(period, options.statistics);

  LoopOptions loop;
  loop.period_s = period;
  // Each wait row may hold the replay up to its timeout (ReplayInput::finished ends the run).
  loop.max_cycles = run_cycles(
      static_cast<double>(end_cycles) +
          static_cast<double>(wait_rows) * (std::ceil(options.waits.timeout_s / period) + 1.0),
      "the replay, its waits and its settle time");
  loop.realtime = options.realtime;
  loop.log = log;
  loop.freeze_at_s = options.freeze_at_s;
  loop.freeze_for_s = options.freeze_for_s;
  loop.observers.push_back(&statistics);
  loop.observers.insert(loop.observers.end(), options.observers.begin(), options.observers.end());
  RunSummary summary = statistics.summary(run_control_loop(task, machine, loop));
  summary.waits = input.waits();
  summary.cycle_time_s = replay.end_time_s() + input.waits().total_s;
  return summary;
}

}  // namespace craneassist::control
