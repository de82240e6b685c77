#include "craneassist/control/trajectory_runner.hpp"

#include <cmath>
#include <stdexcept>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/control/log_row_builder.hpp"
#include "craneassist/control/run_statistics.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/valve_table.hpp"
#include "craneassist/valves/reference_follower.hpp"

namespace craneassist::control {
namespace {

// The plan sampled every period (ahead by the preview) and followed by the reference follower;
// the log row holds the plan's tip in the command columns and the tip error against it.
class TrajectoryTask final : public CycleTask {
 public:
  TrajectoryTask(const config::CraneConfig& config, const input::JointTrajectory& trajectory,
                 double preview_s)
      : model_(config.model),
        trajectory_(trajectory),
        preview_s_(preview_s),
        follower_(config.model, config.control.position_gain_1_s, 1.0 / config.control.rate_hz,
                  config.control.activation_speed_m_s, config.control.activation_error_m),
        measured_(config.model),
        q_plan_(model_.dof()),
        qdot_plan_(model_.dof()),
        q_ref_(model_.dof()),
        qdot_ref_(model_.dof()) {}

  void start(const valves::MachineState& state, double valve_command_period_s) override {
    follower_.set_command_period(valve_command_period_s);
    trajectory_.sample(trajectory_.start_time_s(), q_ref_, qdot_ref_);
    q_ref_j_ = q_ref_;
    follower_.reset(state.valid ? state.q : q_ref_j_);
    if (state.valid) {
      const Eigen::Vector3d tip = dynamics::tip_position(model_, kin_, state.q);
      start_error_m_ = (tip - dynamics::tip_position(model_, kin_, q_ref_j_)).norm();
    }
  }

  CycleStatus step(const CycleTime& time, const valves::MachineState& state, const char*,
                   valves::ValveCommand& command, LogRow& row) noexcept override {
    const int n = model_.dof();
    const double t = time.t_s;
    trajectory_.sample(t + preview_s_, q_ref_, qdot_ref_);
    q_ref_j_ = q_ref_;
    qdot_ref_j_ = qdot_ref_;
    const bool valid = state.valid && state.q.size() == n && state.q.allFinite();
    if (valid) {
      follower_.update(q_ref_j_, qdot_ref_j_, &state.q, command);
    } else {
      follower_.neutral(command);  // no measurement: hold still
      ++invalid_cycles_;
    }

    trajectory_.sample(t, q_plan_, qdot_plan_);
    Eigen::Vector3d tip = Eigen::Vector3d::Constant(NAN), tip_v = tip;
    q_plan_j_ = q_plan_;
    const Eigen::Vector3d tip_plan = dynamics::tip_position(model_, kin_, q_plan_j_);
    if (state.valid) {
      measured_.measure(state);
      tip = measured_.tip();
      tip_v = measured_.tip_velocity();
      const double error = (tip - tip_plan).norm();
      max_error_m_ = std::max(max_error_m_, error);
      sum_sq_error_ += error * error;
      ++error_samples_;
    }
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
      row.q_ref[s] = q_plan_[i];
      row.spool[s] = command.spool[i];
      row.load_pressure[s] = state.valid ? state.load_pressure_pa[i] : NAN;
    }
    row.set_pump(state.pump);
    row.active_limit = "trajectory";
    row.tip_error_m = state.valid ? (tip - tip_plan).norm() : NAN;
    return valid ? CycleStatus::kRunning : CycleStatus::kStopped;
  }

  void fill(TrajectoryRunSummary& s) const {
    s.start_error_m = start_error_m_;
    s.max_tip_error_m = max_error_m_;
    s.rms_tip_error_m = error_samples_ > 0 ? std::sqrt(sum_sq_error_ / error_samples_) : 0.0;
    s.invalid_state_cycles = invalid_cycles_;
  }

 private:
  const dynamics::CraneModel& model_;
  const input::JointTrajectory& trajectory_;
  double preview_s_;
  valves::ReferenceFollower follower_;
  dynamics::KinematicsData kin_;
  LogRowBuilder measured_;  // the measured tip and its velocity
  Eigen::VectorXd q_plan_, qdot_plan_, q_ref_, qdot_ref_;
  dynamics::JointVector q_ref_j_, qdot_ref_j_, q_plan_j_;
  double start_error_m_ = 0.0, max_error_m_ = 0.0, sum_sq_error_ = 0.0;
  int error_samples_ = 0, invalid_cycles_ = 0;
};

}  // namespace

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
  const double preview_s = options.preview ? dynamics::longest_valve_lag_s(model) : 0.0;
  TrajectoryTask task(config, trajectory, preview_s);
  RunStatistics statistics(period);

  LoopOptions loop;
  loop.period_s = period;
  loop.t0_s = trajectory.start_time_s();
  loop.max_cycles =
      run_cycles(std::ceil((trajectory.end_time_s() - loop.t0_s + options.settle_s) / period) + 1.0,
                 "the trajectory and its settle time");
  loop.log = log;
  loop.observers.push_back(&statistics);
  const RunSummary s = statistics.summary(run_control_loop(task, machine, loop));

  TrajectoryRunSummary summary;
  summary.cycles = s.cycles;
  summary.duration_s = s.duration_s;
  summary.wall_time_s = s.wall_time_s;
  summary.energy_j = s.energy_j;
  summary.peak_power_w = s.peak_power_w;
  summary.peak_flow_m3_s = s.peak_flow_m3_s;
  summary.pump_saturated_cycles = s.pump_saturated_cycles;
  summary.log_rows_dropped = s.log_rows_dropped;
  task.fill(summary);
  return summary;
}

}  // namespace craneassist::control
