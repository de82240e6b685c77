#include "craneassist/control/log_row_builder.hpp"

#include <cmath>

#include "craneassist/dynamics/cylinders.hpp"

namespace craneassist::control {

LogRowBuilder::LogRowBuilder(const dynamics::CraneModel& model)
    : model_(model),
      cyl_pos_(model.dof()),
      cyl_arm_(model.dof()),
      hanger_axes_(dynamics::hanger_axes(model)) {
  // Size the working data once (forward kinematics at the zero configuration).
  dynamics::JointVector q = dynamics::JointVector::Zero(model.dof());
  dynamics::tip_jacobian(model_, kin_, q, jac_);
}

void LogRowBuilder::measure(const valves::MachineState& state) noexcept {
  const int n = model_.dof();
  if (state.valid) {
    dynamics::tip_jacobian(model_, kin_, state.q, jac_);
    tip_ = model_.task_from_base * kin_.frames[static_cast<std::size_t>(n)].translation();
    tip_v_ = jac_ * state.qdot;
    dynamics::cylinder_lengths(model_, state.q, cyl_pos_);
    dynamics::cylinder_arms(model_, state.q, cyl_arm_);
    if (model_.grapple.hangs()) {
      const auto angles = dynamics::hanger_joint_angles(
          model_, hanger_axes_, kin_.frames[static_cast<std::size_t>(n)], state.swing_radial_rad,
          state.swing_tangential_rad);
      const double dt = state.t_s - hanger_t_s_;
      for (std::size_t k = 0; k < angles.size(); ++k) {
        // Through +-pi the step is taken modulo 2 pi.
        const double step = std::remainder(angles[k] - hanger_[k], 2.0 * M_PI);
        hanger_rate_[k] = dt > 0.0 ? step / dt : 0.0;
        hanger_[k] = angles[k];
      }
      hanger_t_s_ = state.t_s;
    }
  } else {
    tip_.setZero();
    tip_v_.setZero();
  }
}

void LogRowBuilder::fill(LogRow& row, double t, const Eigen::Vector3d& cmd,
                         const ControllerOutput& out,
                         const valves::MachineState& state) const noexcept {
  const int n = model_.dof();
  row.t = t;
  for (int a = 0; a < 3; ++a) {
    const auto s = static_cast<std::size_t>(a);
    row.cmd[s] = cmd[a];
    row.ref_v[s] = out.ref_tip_velocity_m_s[a];
    row.tip[s] = tip_[a];
    row.tip_v[s] = tip_v_[a];
  }
  for (int i = 0; i < n; ++i) {
    const auto s = static_cast<std::size_t>(i);
    row.q[s] = state.valid ? state.q[i] : NAN;
    row.q_ref[s] = out.q_ref[i];
    row.spool[s] = out.valves.spool[i];
    row.load_pressure[s] = state.valid ? state.load_pressure_pa[i] : NAN;
    row.qdot[s] = state.valid ? state.qdot[i] : NAN;
    row.cylinder_pos[s] = state.valid ? cyl_pos_[i] : NAN;
    row.cylinder_vel[s] = state.valid ? cyl_arm_[i] * state.qdot[i] : NAN;
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
  row.load_kg = state.payload_truth_kg;
  row.swing_rad = state.swing_rad;
  row.swing_radial_rad = state.swing_radial_rad;
  row.swing_tangential_rad = state.swing_tangential_rad;
  row.hanger_rad = hanger_;
  row.hanger_rate_rad_s = hanger_rate_;
  row.payload_estimate_kg = out.load.estimate_kg;
  row.load_moment_ratio = out.load.moment_ratio;
  row.rated_load_kg = out.load.rated_kg;
  row.load_reach_m = out.load.reach_m;
  row.flow_limit_m3s = model_.pump.max_flow_m3_s;
  row.power_limit_w = model_.pump.prime_mover_power_w;
  row.payload_converged = out.load.converged;
  row.load_warning = out.load.warning;
  row.load_overload = out.load.overload;
  row.avail_speed_m_s = out.avail_speed_m_s;
  row.avail_speed_resolved_m_s = out.avail_speed_resolved_m_s;
  row.polytope_volume_m3s3 = out.polytope_volume_m3_s3;
  row.polytope_dim = out.polytope_dim;
  row.polytope_area_m2s2 = out.polytope_area_m2_s2;
  const valves::BaseMeasurement& b = state.base;
  row.base_present = b.present;
  row.base_shared_pump = b.shared_pump;
  row.base_pose = {b.x_m, b.y_m, b.phi_rad};
  row.base_velocity = {b.v_m_s, b.omega_rad_s};
  for (std::size_t i = 0; i < 4; ++i) row.base_motor_flow[i] = b.motor_flow_m3_s[i];
  row.base_flow_sum_m3s = b.motor_flow_sum_m3_s;
  row.base_flow_max_m3s = b.drive_max_flow_m3_s;
}

}  // namespace craneassist::control
