#include "craneassist/studies/sine_path_experiment.hpp"

#include <cmath>
#include <stdexcept>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/control/log_row_builder.hpp"
#include "craneassist/control/run_statistics.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "craneassist/paths/path_scaler.hpp"
#include "craneassist/valves/reference_follower.hpp"

namespace craneassist::studies {

void sine_path(double s, dynamics::JointVector& q, dynamics::JointVector& f1,
               dynamics::JointVector& f2) {
  q.resize(2);
  f1.resize(2);
  f2.resize(2);
  q << M_PI / 6.0 - std::sin(s), -M_PI / 6.0 - 0.5 * std::sin(s);
  f1 << -std::cos(s), -0.5 * std::cos(s);
  f2 << std::sin(s), 0.5 * std::sin(s);
}

dynamics::CraneModel machine_model(const config::CraneConfig& config,
                                   const SinePathOptions& options) {
  dynamics::CraneModel model = config.model;
  if (!options.pump_power_limiter) model.pump.prime_mover_power_w = 1e9;
  return model;
}

namespace {

// The 2R arm on the sine path: the path scaler sets the path speed, the reference follower the
// valves; the log row holds the tip the path commands, the reference and the planned LS power.
class SinePathTask final : public control::CycleTask {
 public:
  SinePathTask(const config::CraneConfig& config, const SinePathOptions& options)
      : model_(config.model),
        options_(options),
        terms_(model_),
        scaler_(model_,
                {1.0 / config.control.rate_hz, options.jerk_max, options.acceleration_max,
                 config.control.flow_reserve, options.power_bound, config.scaling.power_reserve},
                terms_),
        follower_(model_, config.control.position_gain_1_s, 1.0 / config.control.rate_hz),
        measured_(model_) {
    geometry_.d2c_dq2.resize(2);
  }

  void start(const valves::MachineState&, double) override {
    sine_path(0.0, q_ref_, geometry_.f1, geometry_.f2);
    follower_.reset(q_ref_);
  }

  control::CycleStatus step(const control::CycleTime& time, const valves::MachineState& state,
                            const char*, valves::ValveCommand& command,
                            control::LogRow& row) noexcept override {
    const double s = scaler_.state().s;
    sine_path(s, q_ref_, geometry_.f1, geometry_.f2);
    dynamics::cylinder_arms(model_, q_ref_, geometry_.dc_dq);
    for (int i = 0; i < 2; ++i) {
      geometry_.d2c_dq2[i] =
          dynamics::cylinder_arm_slope(model_.cylinders[static_cast<std::size_t>(i)], q_ref_[i]);
    }
    paths::PathScalerInput in;
    in.sdot_request = options_.sdot_request;
    scaler_.update(q_ref_, geometry_, in, out_);
    const double planned = scaling::load_sensing_power(model_, geometry_, out_.terms,
                                                       out_.state.sdot, out_.state.sddot);
    sine_path(out_.state.s, q_ref_, geometry_.f1, geometry_.f2);
    qdot_ref_ = geometry_.f1 * out_.state.sdot;
    follower_.update(q_ref_, qdot_ref_, state.valid ? &state.q : nullptr, command);

    peak_planned_ls_power_w_ = std::max(peak_planned_ls_power_w_, planned);
    peak_path_jerk_ = std::max(peak_path_jerk_, std::abs(out_.state.sdddot));
    if (state.valid) {
      measured_.measure(state);
      const Eigen::Vector3d& tip = measured_.tip();
      const Eigen::Vector3d& tip_v = measured_.tip_velocity();
      dynamics::tip_jacobian(model_, kin_, q_ref_, jac_);
      const Eigen::Vector3d ref_v = jac_ * qdot_ref_;
      const Eigen::Vector3d cmd_v = jac_ * geometry_.f1 * options_.sdot_request;
      for (std::size_t a = 0; a < 3; ++a) {
        const auto e = static_cast<Eigen::Index>(a);
        row.cmd[a] = cmd_v[e];
        row.ref_v[a] = ref_v[e];
        row.tip[a] = tip[e];
        row.tip_v[a] = tip_v[e];
      }
      for (std::size_t i = 0; i < 2; ++i) {
        const auto e = static_cast<Eigen::Index>(i);
        row.q[i] = state.q[e];
        row.q_ref[i] = q_ref_[e];
        row.spool[i] = command.spool[e];
        row.load_pressure[i] = state.load_pressure_pa[e];
      }
    }
    row.t = time.t_s;
    row.set_pump(state.pump);
    row.active_limit = scaling::to_string(out_.limit);
    row.scale = out_.state.sdot / options_.sdot_request;
    row.flow_demand_m3s = out_.speed.flow_per_speed_m3 * options_.sdot_request;
    row.s = out_.state.s;
    row.sdot = out_.state.sdot;
    row.sddot = out_.state.sddot;
    row.sdddot = out_.state.sdddot;
    row.sddot_min = out_.bounds.sddot_min;
    row.sddot_max = out_.bounds.sddot_max;
    row.tip_error_m = 0.0;
    row.ref_power_w = planned;
    return control::CycleStatus::kRunning;
  }

  void fill(SinePathSummary& s) const {
    s.s_final = scaler_.state().s;
    s.peak_planned_ls_power_w = peak_planned_ls_power_w_;
    s.peak_path_jerk = peak_path_jerk_;
  }

 private:
  const dynamics::CraneModel& model_;
  SinePathOptions options_;
  dynamics::RigidBodyTerms terms_;
  paths::PathScaler scaler_;
  valves::ReferenceFollower follower_;
  scaling::PathGeometry geometry_;
  paths::PathScalerOutput out_;
  dynamics::JointVector q_ref_, qdot_ref_;
  control::LogRowBuilder measured_;  // the measured tip and its velocity
  dynamics::KinematicsData kin_;
  dynamics::TaskJacobian jac_;
  double peak_planned_ls_power_w_ = 0.0, peak_path_jerk_ = 0.0;
};

// Counts the cycles the simulated pump's power limiter held the flow back.
class PowerLimitedCycles final : public control::CycleObserver {
 public:
  bool reads_polytope() const noexcept override { return false; }
  void on_cycle(const control::CycleRecord& c) noexcept override {
    cycles += c.state.pump.limit == valves::PumpLimit::kPower;
  }
  long cycles = 0;
};

}  // namespace

SinePathSummary run_sine_path(const config::CraneConfig& config, const SinePathOptions& options,
                              valves::MachineInterface& machine, control::CsvLog* log) {
  if (config.model.dof() != 2) throw std::invalid_argument("the sine path needs a two-joint model");
  const double period = 1.0 / config.control.rate_hz;
  SinePathTask task(config, options);
  control::RunStatistics statistics(period);
  PowerLimitedCycles power_limited;
  control::LoopOptions loop;
  loop.period_s = period;
  loop.max_cycles = control::run_cycles(std::round(options.duration_s / period), "the duration");
  loop.stop_at_end = false;  // the paper's fixed-length run on the simulated arm, as published
  loop.log = log;
  loop.observers = {&statistics, &power_limited};
  const control::RunSummary s = statistics.summary(control::run_control_loop(task, machine, loop));

  SinePathSummary summary;
  summary.cycles = s.cycles;
  summary.energy_j = s.energy_j;
  summary.peak_pump_power_w = s.peak_power_w;
  summary.cycles_power_limited = power_limited.cycles;
  task.fill(summary);
  return summary;
}

}  // namespace craneassist::studies
