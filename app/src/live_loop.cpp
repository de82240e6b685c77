#include "craneassist/app/live_loop.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "craneassist/app/log_row_builder.hpp"

namespace craneassist::app {

LiveSummary run_live(const config::CraneConfig& config, input::CommandSource& source,
                     valves::MachineInterface& machine, const LiveOptions& options, CsvLog* log) {
  ControllerOptions controller_options = options.controller;
  controller_options.valve_command_period_s = machine.command_period_s();
  Controller controller(config, controller_options);
  input::InputMonitor monitor(options.monitor);
  const double period = controller.period_s();
  const long max_cycles = options.duration_s > 0.0
                              ? static_cast<long>(std::ceil(options.duration_s / period - 1e-9))
                              : std::numeric_limits<long>::max();
  const long settle_cycles = static_cast<long>(std::ceil(options.stop_settle_max_s / period));

  valves::MachineState state;
  ControllerOutput out;
  LogRowBuilder builder(config.model);
  LogRow row;
  row.input_source = source.name();
  input::OperatorCommand sample;
  input::MonitorOutput mon;
  LiveStatus status;
  LiveSummary summary;
  Eigen::Vector3d last_tip = Eigen::Vector3d::Zero();
  bool last_tip_valid = false;
  input::ReplayRow last_recorded{0.0, Eigen::Vector3d::Zero(), false};
  const Eigen::Vector3d no_tip =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  const Eigen::Vector3d no_command = no_tip;
  std::vector<input::ReplayRow>* record = options.record;
  if (record != nullptr) {
    record->clear();
    record->reserve(options.record_capacity);
  }

  machine.read(state);
  controller.reset(state);
  const auto wall_start = std::chrono::steady_clock::now();
  auto next_tick = wall_start;
  long stop_requested_at = -1;  // cycle of the stop request (quit, or a machine fault)
  const char* stop_cause = "operator quit";
  long k = 0;
  double t = 0.0;
  for (; k < max_cycles; ++k) {
    t = static_cast<double>(k) * period;
    if (options.realtime) {
      const double late =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - next_tick).count();
      summary.max_late_s = std::max(summary.max_late_s, late);
    }
    const double now = options.realtime ? steady_now_s() : t;
    const valves::BackendStatus machine_status = machine.read(state);
    if (machine_status == valves::BackendStatus::kFault && !summary.machine_fault) {
      // A latched machine fault (CAN) ends the run: the machine is already safe (blocked), and
      // the loop stops its reference as for a quit.
      summary.machine_fault = true;
      if (stop_requested_at < 0) {
        stop_requested_at = k;
        stop_cause = "machine fault";
      }
    }
    builder.measure(state);
    source.begin_cycle(now, state.valid ? builder.tip() : no_tip);
    const input::SourceState source_state = source.poll(sample);
    monitor.update(source_state, sample, now, mon);
    if (stop_requested_at < 0 && options.stop != nullptr &&
        options.stop->load(std::memory_order_relaxed)) {
      stop_requested_at = k;
    }
    const bool stopping_for_quit = stop_requested_at >= 0;
    const bool enabled = mon.enabled && !stopping_for_quit;
    // Whatever keeps the operator's command from passing (an input fault, the deadman, not
    // re-armed, quit), the controller gets a non-finite command: its jerk-limited stop along
    // the current direction, then neutral valves (docs/joystick.md#input-safety).
    const Eigen::Vector3d& cmd = enabled ? mon.v_m_s : no_command;
    const ControllerStatus cstatus = controller.update(state, cmd, out);
    machine.write(out.valves);

    const bool at_rest = out.qdot_ref.isZero(0.0) && out.sddot == 0.0;
    const char* status_text = status_word(cstatus);
    const char* reason = stopping_for_quit ? stop_cause : to_string(mon.fault);
    if (enabled && cstatus != ControllerStatus::kRunning) reason = "measurement invalid";

    if (record != nullptr) {
      // A stop row for a non-finite command (the replay format holds no NaN).
      const input::ReplayRow now_row{t, enabled ? cmd : Eigen::Vector3d::Zero(), !enabled};
      if (k == 0 || now_row.stop != last_recorded.stop || now_row.v_m_s != last_recorded.v_m_s) {
        if (record->size() < options.record_capacity) {
          record->push_back(now_row);
        } else {
          ++summary.record_rows_dropped;
        }
        last_recorded = now_row;
      }
    }

    builder.fill(row, t, cmd, out, state);
    row.status = status_text;
    row.stop_reason = reason;
    row.deadman = mon.deadman;
    if (log != nullptr) log->push(row);
    for (CycleObserver* o : options.observers) o->on_cycle(row);

    const double speed = builder.tip_velocity().norm();
    summary.peak_tip_speed_m_s = std::max(summary.peak_tip_speed_m_s, speed);
    // The path over valid measurements only (an invalid one, e.g. a CAN fault, has no tip).
    if (k > 0 && state.valid && last_tip_valid) {
      summary.tip_path_m += (builder.tip() - last_tip).norm();
    }
    last_tip = builder.tip();
    last_tip_valid = state.valid;
    summary.enabled_cycles += enabled;

    if (options.status_board != nullptr) {
      status.t = t;
      status.tip = builder.tip();
      status.tip_v = builder.tip_velocity();
      status.cmd = cmd;
      status.status = status_text;
      status.stop_reason = reason;
      status.fault = mon.fault;
      status.source = source_state;
      status.deadman = mon.deadman;
      status.input_age_s = mon.input_age_s;
      status.disconnects = monitor.disconnects();
      status.reconnects = monitor.reconnects();
      options.status_board->publish(status);
    }

    machine.advance(period);
    if (stopping_for_quit && (at_rest || k - stop_requested_at >= settle_cycles)) {
      ++k;
      break;
    }
    if (options.realtime) {
      next_tick += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(period));
      std::this_thread::sleep_until(next_tick);
    }
  }
  // The recording ends with the last cycle, so a replay of it runs as long as the session.
  if (record != nullptr && !record->empty() && record->back().t_s < t) {
    record->push_back({t, last_recorded.v_m_s, last_recorded.stop});
  }
  summary.cycles = static_cast<int>(k);
  summary.duration_s = static_cast<double>(k) * period;
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  summary.disconnects = monitor.disconnects();
  summary.reconnects = monitor.reconnects();
  if (log != nullptr) summary.log_rows_dropped = log->close();
  return summary;
}

}  // namespace craneassist::app
