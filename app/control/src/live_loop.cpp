#include "craneassist/control/live_loop.hpp"

#include <cmath>
#include <limits>
#include <optional>

#include "craneassist/control/run_statistics.hpp"
#include "craneassist/control/tip_command_task.hpp"

namespace craneassist::control {
namespace {

// Records the command the controller got, in the replay format: a row where it changes, a stop
// row for no command (the replay format holds no NaN), and a last row at the session's final
// cycle so a replay of it runs as long as the session. The session ends where the loop's stop
// begins (quit, fault, end of run): a replay of the record ends with the same stop.
// Preallocated; rows beyond the capacity are counted.
class RecordingObserver final : public CycleObserver {
 public:
  RecordingObserver(std::vector<input::ReplayRow>& record, std::size_t capacity)
      : record_(record), capacity_(capacity) {
    record_.clear();
    record_.reserve(capacity);
  }
  bool reads_polytope() const noexcept override { return false; }
  void on_cycle(const CycleRecord& c) noexcept override {
    if (c.stop_cause != nullptr) return;
    last_t_s_ = c.time.t_s;
    const Eigen::Vector3d cmd(c.row.cmd[0], c.row.cmd[1], c.row.cmd[2]);
    const bool stop = !cmd.allFinite();
    const input::ReplayRow row{c.time.t_s, stop ? Eigen::Vector3d::Zero() : cmd, stop};
    if (c.time.k == 0 || row.stop != last_.stop || row.v_m_s != last_.v_m_s) {
      if (record_.size() < capacity_) {
        record_.push_back(row);
      } else {
        ++dropped_;
      }
      last_ = row;
    }
  }
  void on_finish(const CycleTime&, const valves::MachineState&) override {
    if (!record_.empty() && record_.back().t_s < last_t_s_) {
      record_.push_back({last_t_s_, last_.v_m_s, last_.stop});
    }
  }
  std::size_t dropped() const { return dropped_; }

 private:
  std::vector<input::ReplayRow>& record_;
  std::size_t capacity_;
  input::ReplayRow last_{0.0, Eigen::Vector3d::Zero(), false};
  double last_t_s_ = 0.0;
  std::size_t dropped_ = 0;
};

// Publishes the loop's latest state to the status board (try_lock: skips rather than waits).
class StatusObserver final : public CycleObserver {
 public:
  StatusObserver(LiveStatusBoard& board, const MonitoredInput& input)
      : board_(board), input_(input) {}
  bool reads_polytope() const noexcept override { return false; }
  void on_cycle(const CycleRecord& c) noexcept override {
    const LogRow& r = c.row;
    status_.t = c.time.t_s;
    status_.tip = Eigen::Vector3d(r.tip[0], r.tip[1], r.tip[2]);
    status_.tip_v = Eigen::Vector3d(r.tip_v[0], r.tip_v[1], r.tip_v[2]);
    status_.cmd = Eigen::Vector3d(r.cmd[0], r.cmd[1], r.cmd[2]);
    status_.status = r.status;
    status_.stop_reason = r.stop_reason;
    status_.fault = input_.last().fault;
    status_.source = input_.source_state();
    status_.deadman = input_.last().deadman;
    status_.input_age_s = input_.last().input_age_s;
    status_.disconnects = input_.monitor().disconnects();
    status_.reconnects = input_.monitor().reconnects();
    status_.base = c.state.base;
    board_.publish(status_);
  }

 private:
  LiveStatusBoard& board_;
  const MonitoredInput& input_;
  LiveStatus status_;
};

}  // namespace

LiveSummary run_live(const config::CraneConfig& config, input::CommandSource& source,
                     valves::MachineInterface& machine, const LiveOptions& options, CsvLog* log) {
  MonitoredInput input(source, options.monitor);
  TipCommandTask task(config, options.controller, input);
  task.set_base(options.base);
  const double period = task.period_s();
  RunStatistics statistics(period);

  LoopOptions loop;
  loop.period_s = period;
  loop.max_cycles = options.duration_s > 0.0
                        ? run_cycles(std::ceil(options.duration_s / period - 1e-9), "--duration")
                        : std::numeric_limits<long>::max();
  loop.realtime = options.realtime;
  loop.realtime_setup = options.realtime_setup;
  loop.stop = options.stop;
  loop.stop_settle_max_s = options.stop_settle_max_s;
  loop.log = log;
  loop.observers.push_back(&statistics);
  std::optional<RecordingObserver> recording;
  if (options.record != nullptr) {
    recording.emplace(*options.record, options.record_capacity);
    loop.observers.push_back(&*recording);
  }
  std::optional<StatusObserver> status;
  if (options.status_board != nullptr) {
    status.emplace(*options.status_board, input);
    loop.observers.push_back(&*status);
  }
  loop.observers.insert(loop.observers.end(), options.observers.begin(), options.observers.end());

  const LoopSummary ran = run_control_loop(task, machine, loop);
  const RunSummary stats = statistics.summary(ran);
  LiveSummary summary;
  summary.cycles = ran.cycles;
  summary.load = stats.load;
  summary.stop = stats.stop;
  summary.swing = stats.swing;
  summary.peak_spool_step = stats.peak_spool_step;
  summary.duration_s = ran.duration_s;
  summary.wall_time_s = ran.wall_time_s;
  summary.max_late_s = ran.max_late_s();
  summary.peak_tip_speed_m_s = stats.peak_tip_speed_m_s;
  summary.tip_path_m = stats.tip_path_m;
  summary.enabled_cycles = stats.cycles - stats.input_stop_cycles - ran.stop_cycles;
  summary.disconnects = input.monitor().disconnects();
  summary.reconnects = input.monitor().reconnects();
  summary.log_rows_dropped = ran.log_rows_dropped;
  summary.record_rows_dropped = recording ? recording->dropped() : 0;
  summary.machine_fault = ran.machine_fault;
  summary.end_stop = ran.end_stop;
  summary.stop_cycles = ran.stop_cycles;
  summary.realtime_result = ran.realtime_result;
  summary.timing = ran.timing;
  return summary;
}

}  // namespace craneassist::control
