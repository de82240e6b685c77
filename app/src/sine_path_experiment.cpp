#include "craneassist/app/sine_path_experiment.hpp"

#include <cmath>
#include <stdexcept>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "craneassist/scaling/path_scaler.hpp"
#include "craneassist/valves/reference_follower.hpp"

namespace craneassist::app {

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

SinePathSummary run_sine_path(const config::CraneConfig& config, const SinePathOptions& options,
                              valves::MachineInterface& machine, CsvLog* log) {
  const auto& model = config.model;
  if (model.dof() != 2) throw std::invalid_argument("the sine path needs a two-joint model");
  const double period = 1.0 / config.control.rate_hz;
  dynamics::RigidBodyTerms terms(model);
  scaling::PathScaler scaler(
      model,
      {period, options.jerk_max, options.acceleration_max, config.control.flow_reserve,
       options.power_bound, config.scaling.power_reserve},
      terms);
  valves::ReferenceFollower follower(model, config.control.position_gain_1_s, period);

  scaling::PathGeometry geometry;
  dynamics::JointVector q_ref, qdot_ref;
  sine_path(0.0, q_ref, geometry.f1, geometry.f2);
  follower.reset(q_ref);
  dynamics::KinematicsData kin;
  dynamics::TaskJacobian jac;
  valves::MachineState state;
  valves::ValveCommand command;
  scaling::PathScalerOutput out;
  LogRow row;
  SinePathSummary summary;
  const int cycles = static_cast<int>(std::lround(options.duration_s / period));
  for (int k = 0; k < cycles; ++k) {
    machine.read(state);
    const double s = scaler.state().s;
    sine_path(s, q_ref, geometry.f1, geometry.f2);
    dynamics::cylinder_arms(model, q_ref, geometry.dc_dq);
    geometry.d2c_dq2.resize(2);
    for (int i = 0; i < 2; ++i) {
      geometry.d2c_dq2[i] =
          dynamics::cylinder_arm_slope(model.cylinders[static_cast<std::size_t>(i)], q_ref[i]);
    }
    scaling::PathScalerInput in;
    in.sdot_request = options.sdot_request;
    scaler.update(q_ref, geometry, in, out);
    const double planned =
        scaling::load_sensing_power(model, geometry, out.terms, out.state.sdot, out.state.sddot);
    sine_path(out.state.s, q_ref, geometry.f1, geometry.f2);
    qdot_ref = geometry.f1 * out.state.sdot;
    follower.update(q_ref, qdot_ref, state.valid ? &state.q : nullptr, command);
    machine.write(command);

    summary.peak_pump_power_w = std::max(summary.peak_pump_power_w, state.pump.power_w);
    summary.peak_planned_ls_power_w = std::max(summary.peak_planned_ls_power_w, planned);
    summary.cycles_power_limited += state.pump.limit == valves::PumpLimit::kPower;
    summary.peak_path_jerk = std::max(summary.peak_path_jerk, std::abs(out.state.sdddot));
    if (log != nullptr && state.valid) {
      dynamics::tip_jacobian(model, kin, state.q, jac);
      const Eigen::Vector3d tip = model.task_from_base * kin.frames[2].translation();
      const Eigen::Vector3d tip_v = jac * state.qdot;
      dynamics::tip_jacobian(model, kin, q_ref, jac);
      const Eigen::Vector3d ref_v = jac * qdot_ref;
      const Eigen::Vector3d cmd_v = jac * geometry.f1 * options.sdot_request;
      row.t = k * period;
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
        row.q_ref[i] = q_ref[e];
        row.spool[i] = command.spool[e];
        row.load_pressure[i] = state.load_pressure_pa[e];
      }
      row.set_pump(state.pump);
      row.active_limit = scaling::to_string(out.limit);
      row.scale = out.state.sdot / options.sdot_request;
      row.flow_demand_m3s = out.speed.flow_per_speed_m3 * options.sdot_request;
      row.s = out.state.s;
      row.sdot = out.state.sdot;
      row.sddot = out.state.sddot;
      row.sdddot = out.state.sdddot;
      row.sddot_min = out.bounds.sddot_min;
      row.sddot_max = out.bounds.sddot_max;
      row.tip_error_m = 0.0;
      row.ref_power_w = planned;
      log->push(row);
    }
    machine.advance(period);
  }
  machine.read(state);
  summary.cycles = cycles;
  summary.s_final = scaler.state().s;
  summary.energy_j = state.pump.energy_j;
  return summary;
}

}  // namespace craneassist::app
