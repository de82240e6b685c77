#include "craneassist/app/trajectory_runner.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/valves/reference_follower.hpp"

namespace craneassist::app {

TrajectoryRunSummary run_trajectory(const config::CraneConfig& config,
                                    const input::JointTrajectory& trajectory,
                                    valves::MachineInterface& machine,
                                    const TrajectoryRunOptions& options, CsvLog* log) {
  const auto& model = config.model;
  const int n = model.dof();
  if (trajectory.joints() != n || trajectory.empty()) {
    throw std::invalid_argument("the trajectory has " + std::to_string(trajectory.joints()) +
                                " joints, the crane " + std::to_string(n));
  }
  const double period = 1.0 / config.control.rate_hz;
  const double preview_s =
      options.preview ? model.valves.delay_s + model.valves.time_constant_s : 0.0;
  const double t0 = trajectory.start_time_s();
  const int cycles =
      static_cast<int>(std::ceil((trajectory.end_time_s() - t0 + options.settle_s) / period)) + 1;

  valves::ReferenceFollower follower(model, config.control.position_gain_1_s, period,
                                     config.control.activation_speed_m_s,
                                     config.control.activation_error_m);
  follower.set_command_period(machine.command_period_s());
  valves::MachineState state;
  valves::ValveCommand command;
  dynamics::KinematicsData kin;
  dynamics::TaskJacobian jac;
  Eigen::VectorXd q_plan(n), qdot_plan(n), q_ref(n), qdot_ref(n);
  dynamics::JointVector q_ref_j(n), qdot_ref_j(n), q_plan_j(n);
  LogRow row;
  TrajectoryRunSummary summary;
  double sum_sq_error = 0.0;
  int error_samples = 0;

  machine.read(state);
  trajectory.sample(t0, q_ref, qdot_ref);
  q_ref_j = q_ref;
  follower.reset(state.valid ? state.q : q_ref_j);
  if (state.valid) {
    const Eigen::Vector3d tip = dynamics::tip_position(model, kin, state.q);
    summary.start_error_m = (tip - dynamics::tip_position(model, kin, q_ref_j)).norm();
  }
  const auto wall_start = std::chrono::steady_clock::now();
  for (int k = 0; k < cycles; ++k) {
    const double t = t0 + k * period;
    machine.read(state);
    trajectory.sample(t + preview_s, q_ref, qdot_ref);
    q_ref_j = q_ref;
    qdot_ref_j = qdot_ref;
    if (state.valid && state.q.size() == n && state.q.allFinite()) {
      follower.update(q_ref_j, qdot_ref_j, &state.q, command);
    } else {
      follower.neutral(command);  // no measurement: hold still
      ++summary.invalid_state_cycles;
    }
    machine.write(command);

    trajectory.sample(t, q_plan, qdot_plan);
    Eigen::Vector3d tip = Eigen::Vector3d::Constant(NAN), tip_v = tip;
    q_plan_j = q_plan;
    const Eigen::Vector3d tip_plan = dynamics::tip_position(model, kin, q_plan_j);
    if (state.valid) {
      dynamics::tip_jacobian(model, kin, state.q, jac);
      tip = model.task_from_base * kin.frames[static_cast<std::size_t>(n)].translation();
      tip_v = jac * state.qdot;
      const double error = (tip - tip_plan).norm();
      summary.max_tip_error_m = std::max(summary.max_tip_error_m, error);
      sum_sq_error += error * error;
      ++error_samples;
    }
    summary.peak_power_w = std::max(summary.peak_power_w, state.pump.power_w);
    summary.peak_flow_m3_s = std::max(summary.peak_flow_m3_s, state.pump.flow_m3_s);
    summary.pump_saturated_cycles += state.pump.limit != valves::PumpLimit::kNone;

    if (log != nullptr) {
      row.t = t;
      for (int a = 0; a < 3; ++a) {
        const auto s = static_cast<std::size_t>(a);
        row.cmd[s] = tip_plan[a];  // the plan's tip (the log's command columns)
        row.ref_v[s] = 0.0;
        row.tip[s] = tip[a];
        row.tip_v[s] = tip_v[a];
      }
      for (int i = 0; i < n; ++i) {
        const auto s = static_cast<std::size_t>(i);
        row.q[s] = state.valid ? state.q[i] : NAN;
        row.q_ref[s] = q_plan[i];
        row.spool[s] = command.spool[i];
        row.load_pressure[s] = state.valid ? state.load_pressure_pa[i] : NAN;
      }
      row.set_pump(state.pump);
      row.active_limit = "trajectory";
      row.tip_error_m = state.valid ? (tip - tip_plan).norm() : NAN;
      log->push(row);
    }
    machine.advance(period);
  }
  machine.read(state);
  summary.cycles = cycles;
  summary.duration_s = cycles * period;
  summary.energy_j = state.pump.energy_j;
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  summary.rms_tip_error_m = error_samples > 0 ? std::sqrt(sum_sq_error / error_samples) : 0.0;
  if (log != nullptr) summary.log_rows_dropped = log->close();
  return summary;
}

}  // namespace craneassist::app
