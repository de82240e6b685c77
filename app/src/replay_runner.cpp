#include "craneassist/app/replay_runner.hpp"

#include <chrono>
#include <cmath>
#include <thread>

namespace craneassist::app {

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double na = a.norm(), nb = b.norm();
  if (na == 0.0 || nb == 0.0) return 0.0;
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

RunSummary run_replay(const config::CraneConfig& config, const input::Replay& replay,
                      valves::MachineInterface& machine, const RunOptions& options, CsvLog* log) {
  const auto& model = config.model;
  const int n = model.dof();
  Controller controller(config, options.controller);
  const double period = controller.period_s();
  const int cycles =
      static_cast<int>(std::ceil((replay.end_time_s() + options.settle_s) / period - 1e-9)) + 1;

  input::ReplayCursor cursor(replay);
  valves::MachineState state;
  ControllerOutput out;
  dynamics::KinematicsData kin;
  dynamics::TaskJacobian jac;
  LogRow row;
  RunSummary summary;
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
    if (controller.update(state, cmd, out) != ControllerStatus::kRunning) ++summary.stopped_cycles;
    summary.peak_path_jerk = std::max(summary.peak_path_jerk, std::abs(out.sdddot));
    machine.write(out.valves);

    // Measured tip position and velocity.
    Eigen::Vector3d tip = Eigen::Vector3d::Zero(), tip_v = Eigen::Vector3d::Zero();
    if (state.valid) {
      dynamics::tip_jacobian(model, kin, state.q, jac);
      tip = model.task_from_base * kin.frames[static_cast<std::size_t>(n)].translation();
      tip_v = jac * state.qdot;
    }
    if (cmd != last_cmd) {
      last_cmd = cmd;
      cmd_since_s = t;
    }
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

    if (log != nullptr) {
      row.t = t;
      for (int a = 0; a < 3; ++a) {
        const auto s = static_cast<std::size_t>(a);
        row.cmd[s] = cmd[a];
        row.ref_v[s] = out.ref_tip_velocity_m_s[a];
        row.tip[s] = tip[a];
        row.tip_v[s] = tip_v[a];
      }
      for (int i = 0; i < n; ++i) {
        const auto s = static_cast<std::size_t>(i);
        row.q[s] = state.valid ? state.q[i] : NAN;
        row.q_ref[s] = out.q_ref[i];
        row.spool[s] = out.valves.spool[i];
        row.load_pressure[s] = state.valid ? state.load_pressure_pa[i] : NAN;
      }
      row.set_pump(state.pump);
      row.active_limit = scaling::to_string(out.limit);
      row.scale = out.scale;
      row.s = out.s;
      row.sdot = out.sdot;
      row.sddot = out.sddot;
      row.sdddot = out.sdddot;
      row.sddot_min = out.sddot_min;
      row.sddot_max = out.sddot_max;
      row.tip_error_m = out.tip_error_m;
      row.ref_power_w = out.ref_power_w;
      row.flow_demand_m3s = out.flow_demand_m3_s;
      log->push(row);
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
