#include "craneassist/app/replay_runner.hpp"

#include <chrono>
#include <cmath>
#include <thread>

#include "craneassist/app/log_row_builder.hpp"

namespace craneassist::app {

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double na = a.norm(), nb = b.norm();
  if (na == 0.0 || nb == 0.0) return 0.0;
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

RunSummary run_replay(const config::CraneConfig& config, const input::Replay& replay,
                      valves::MachineInterface& machine, const RunOptions& options, CsvLog* log) {
  const auto& model = config.model;
  ControllerOptions controller_options = options.controller;
  controller_options.valve_command_period_s = machine.command_period_s();
  Controller controller(config, controller_options);
  const double period = controller.period_s();
  const int cycles =
      static_cast<int>(std::ceil((replay.end_time_s() + options.settle_s) / period - 1e-9)) + 1;

  input::ReplayCursor cursor(replay);
  valves::MachineState state;
  ControllerOutput out;
  LogRowBuilder builder(model);
  LogRow row;
  row.input_source = "replay";
  RunSummary summary;
  MotionQuality quality(period);
  double sum_sq_direction = 0.0;
  Eigen::Vector3d last_cmd = Eigen::Vector3d::Zero();
  double cmd_since_s = 0.0;
  Eigen::Vector3d last_tip = Eigen::Vector3d::Zero();

  machine.read(state);
  controller.reset(state);
  bool frozen_once = false;
  const auto wall_start = std::chrono::steady_clock::now();
  auto next_tick = wall_start;
  for (int k = 0; k < cycles; ++k) {
    const double t = k * period;
    machine.read(state);
    const Eigen::Vector3d cmd = cursor.command_at(t);
    const ControllerStatus status = controller.update(state, cmd, out);
    const bool input_stop = !cmd.allFinite();  // a stop row
    if (status != ControllerStatus::kRunning) ++summary.stopped_cycles;
    summary.neutral_valve_cycles += status == ControllerStatus::kStopped;
    summary.input_stop_cycles += input_stop;
    summary.peak_path_jerk = std::max(summary.peak_path_jerk, std::abs(out.sdddot));
    machine.write(out.valves);

    // Measured tip position and velocity.
    builder.measure(state);
    const Eigen::Vector3d& tip = builder.tip();
    const Eigen::Vector3d& tip_v = builder.tip_velocity();
    if (!(cmd == last_cmd || (input_stop && !last_cmd.allFinite()))) {
      last_cmd = cmd;
      cmd_since_s = t;
    }
    quality.add(t, cmd, tip, tip_v);
    const double speed = tip_v.norm();
    summary.peak_tip_speed_m_s = std::max(summary.peak_tip_speed_m_s, speed);
    if (k > 0) summary.tip_path_m += (tip - last_tip).norm();
    last_tip = tip;
    // Direction statistics: the reference has been on the command (direction blending done)
    // for the settling window, and the tip moves.
    if (!(cmd.norm() > 0.0 && angle_deg(cmd, out.ref_tip_velocity_m_s) < 0.5)) {
      cmd_since_s = t + period;  // not on the command yet: the window starts later
    }
    if (cmd.norm() > 0.0 && speed > options.min_speed_m_s &&
        t - cmd_since_s >= options.steady_after_s) {
      const double err = angle_deg(cmd, tip_v);
      summary.max_direction_error_deg = std::max(summary.max_direction_error_deg, err);
      sum_sq_direction += err * err;
      ++summary.direction_samples;
    }
    if (cmd.norm() > 0.0 && out.ref_tip_velocity_m_s.norm() > 1e-9) {
      summary.max_reference_direction_error_deg = std::max(
          summary.max_reference_direction_error_deg, angle_deg(cmd, out.ref_tip_velocity_m_s));
    }
    summary.peak_power_w = std::max(summary.peak_power_w, state.pump.power_w);
    summary.peak_flow_m3_s = std::max(summary.peak_flow_m3_s, state.pump.flow_m3_s);
    summary.pump_saturated_cycles += state.pump.limit != valves::PumpLimit::kNone;
    ++summary.limit_cycles[static_cast<std::size_t>(out.limit)];

    if (log != nullptr || !options.observers.empty()) {
      builder.fill(row, t, cmd, out, state);
      row.status = status_word(status);
      row.stop_reason = input_stop                             ? "replay stop row"
                        : status == ControllerStatus::kRunning ? ""
                                                               : "measurement invalid";
      row.deadman = !input_stop;
      if (log != nullptr) log->push(row);
      for (CycleObserver* o : options.observers) o->on_cycle(row);
    }

    machine.advance(period);
    if (!frozen_once && options.freeze_at_s >= 0.0 && t >= options.freeze_at_s) {
      std::this_thread::sleep_for(std::chrono::duration<double>(options.freeze_for_s));
      next_tick = std::chrono::steady_clock::now();
      frozen_once = true;
    }
    if (options.realtime) {
      next_tick += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(period));
      std::this_thread::sleep_until(next_tick);
    }
  }
  machine.read(state);
  summary.feel = quality.result();
  summary.cycles = cycles;
  summary.duration_s = cycles * period;
  summary.energy_j = state.pump.energy_j;
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  summary.rms_direction_error_deg =
      summary.direction_samples > 0 ? std::sqrt(sum_sq_direction / summary.direction_samples) : 0.0;
  if (log != nullptr) summary.log_rows_dropped = log->close();
  return summary;
}

}  // namespace craneassist::app
