#include "craneassist/control/replay_runner.hpp"

#include <cmath>

#include "craneassist/control/tip_command_task.hpp"

namespace craneassist::control {

RunSummary run_replay(const config::CraneConfig& config, const input::Replay& replay,
                      valves::MachineInterface& machine, const RunOptions& options, CsvLog* log) {
  ReplayInput input(replay);
  TipCommandTask task(config, options.controller, input);
  const double period = task.period_s();
  RunStatistics statistics(period, options.statistics);

  LoopOptions loop;
  loop.period_s = period;
  loop.max_cycles =
      run_cycles(std::ceil((replay.end_time_s() + options.settle_s) / period - 1e-9) + 1.0,
                 "the replay and its settle time");
  loop.realtime = options.realtime;
  loop.log = log;
  loop.freeze_at_s = options.freeze_at_s;
  loop.freeze_for_s = options.freeze_for_s;
  loop.observers.push_back(&statistics);
  loop.observers.insert(loop.observers.end(), options.observers.begin(), options.observers.end());
  return statistics.summary(run_control_loop(task, machine, loop));
}

}  // namespace craneassist::control
