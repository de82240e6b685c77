#include "telemetry_observer.hpp"

#include <algorithm>
#include <type_traits>

#include "craneassist/control/log_fields.hpp"
#include "craneassist/dynamics/urdf.hpp"

namespace craneassist::cli {

namespace {

// Every field a log row and a telemetry frame share, as (row field, frame field) pairs: one list
// for both directions. The first n joints only.
template <class Row, class Frame, class Copy>
void each_field(Row& row, Frame& f, int n, Copy copy) {
  for (int i = 0; i < n; ++i) {
    const auto s = static_cast<std::size_t>(i);
    copy(row.q[s], f.q[s]);
    copy(row.q_ref[s], f.q_ref[s]);
    copy(row.qdot[s], f.qdot[s]);
    copy(row.cylinder_pos[s], f.cylinder_pos_m[s]);
    copy(row.cylinder_vel[s], f.cylinder_vel_m_s[s]);
    copy(row.load_pressure[s], f.load_pressure_pa[s]);
    copy(row.spool[s], f.spool[s]);
  }
  copy(row.t, f.t_s);
  copy(row.tip, f.tip_m);
  copy(row.tip_v, f.tip_v_m_s);
  copy(row.cmd, f.command_m_s);
  copy(row.ref_v, f.reference_m_s);
  copy(row.pump_flow_m3s, f.pump_flow_m3_s);
  copy(row.pump_pressure_pa, f.pump_pressure_pa);
  copy(row.pump_power_w, f.pump_power_w);
  copy(row.energy_j, f.energy_j);
  copy(row.flow_demand_m3s, f.flow_demand_m3_s);
  copy(row.ref_power_w, f.ref_power_w);
  copy(row.scale, f.scale);
  copy(row.s, f.s);
  copy(row.sdot, f.sdot);
  copy(row.sddot, f.sddot);
  copy(row.sdddot, f.sdddot);
  copy(row.sddot_min, f.sddot_min);
  copy(row.sddot_max, f.sddot_max);
  copy(row.tip_error_m, f.tip_error_m);
  copy(row.status, f.status);
  copy(row.stop_reason, f.stop_reason);
  copy(row.active_limit, f.active_limit);
  copy(row.pump_limit, f.pump_limit);
  copy(row.input_source, f.input_source);
  copy(row.deadman, f.deadman);
  copy(row.loop_latency_max_s, f.loop_latency_max_s);
  copy(row.loop_compute_s, f.loop_compute_s);
  copy(row.loop_overruns, f.loop_overruns);
  copy(row.avail_speed_m_s, f.avail_speed_m_s);
  copy(row.avail_speed_resolved_m_s, f.avail_speed_resolved_m_s);
  copy(row.polytope_dim, f.polytope_dim);
  copy(row.polytope_volume_m3s3, f.polytope_volume_m3_s3);
  copy(row.polytope_area_m2s2, f.polytope_area_m2_s2);
  copy(row.load_kg, f.load_truth_kg);
  copy(row.payload_estimate_kg, f.payload_estimate_kg);
  copy(row.load_moment_ratio, f.load_moment_ratio);
  copy(row.rated_load_kg, f.rated_load_kg);
  copy(row.load_reach_m, f.load_reach_m);
  copy(row.payload_converged, f.payload_converged);
  copy(row.load_warning, f.load_warning);
  copy(row.load_overload, f.load_overload);
  copy(row.swing_rad, f.swing_rad);
  copy(row.swing_radial_rad, f.swing_radial_rad);
  copy(row.swing_tangential_rad, f.swing_tangential_rad);
  copy(row.hanger_rad, f.hanger_rad);
  copy(row.hanger_rate_rad_s, f.hanger_rate_rad_s);
  copy(row.base_present, f.base_present);
  copy(row.base_shared_pump, f.base_shared_pump);
  copy(row.base_pose, f.base_pose);
  copy(row.base_velocity, f.base_velocity);
  copy(row.base_command, f.base_command);
  copy(row.base_motor_flow, f.base_motor_flow_m3_s);
  copy(row.base_flow_sum_m3s, f.base_flow_sum_m3_s);
  copy(row.base_flow_max_m3s, f.base_flow_max_m3_s);
}

}  // namespace

void to_frame(const control::LogRow& row, int dof, dds::TelemetryFrame& f) noexcept {
  const int n = std::min(dof, dds::kMaxJoints);
  f.dof = n;
  each_field(row, f, n, [](const auto& from, auto& to) {
    to = static_cast<std::remove_reference_t<decltype(to)>>(from);
  });
  // Every numeric field of the table (telemetry_info's field_names: with the base's).
  f.value_count = control::flat_field_values(row, n, true, f.values.data(), dds::kMaxFieldValues);
}

void from_frame(const dds::TelemetryFrame& f, control::LogRow& row) noexcept {
  const int n = std::clamp(f.dof, 0, std::min(dds::kMaxJoints, control::LogRow::kMaxJoints));
  each_field(row, f, n, [](auto& to, const auto& from) {
    to = static_cast<std::remove_reference_t<decltype(to)>>(from);
  });
}

void TelemetryObserver::on_cycle(const control::CycleRecord& cycle) noexcept {
  to_frame(cycle.row, dof_, frame_);
  frame_.cycle = cycle_++;
  publisher_.push(frame_);
}

dds::TelemetryInfo telemetry_info(const config::CraneConfig& config, const char* backend) {
  dds::TelemetryInfo info;
  const auto& m = config.model;
  info.crane = m.name;
  info.backend = backend;
  info.pump_mode = dynamics::to_string(m.pump.mode);
  for (const auto& j : m.joints) {
    info.joint_names.push_back(j.name);
    info.joint_prismatic.push_back(j.type == dynamics::JointType::kPrismatic);
  }
  if (m.grapple.hangs()) {
    info.hanger_joint_names.assign(dynamics::kHangerJointNames.begin(),
                                   dynamics::kHangerJointNames.end());
  }
  for (auto& f : control::flat_fields(std::min(m.dof(), dds::kMaxJoints), true)) {
    // A per-joint unit "rad or m" ("rad/s or m/s"): the joint's own (name.1 is the first joint).
    const auto either = f.unit.find(" or ");
    const auto dot = f.name.rfind('.');
    if (either != std::string::npos && dot != std::string::npos) {
      const std::size_t joint = std::stoul(f.name.substr(dot + 1)) - 1;
      const bool prismatic =
          joint < m.joints.size() && m.joints[joint].type == dynamics::JointType::kPrismatic;
      f.unit = prismatic ? f.unit.substr(either + 4) : f.unit.substr(0, either);
    }
    info.field_names.push_back(std::move(f.name));
    info.field_units.push_back(std::move(f.unit));
  }
  info.flow_limit_m3_s = m.pump.max_flow_m3_s;
  info.power_limit_w = m.pump.prime_mover_power_w;
  // crane_from_base is orthonormal: its inverse is its transpose.
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      info.base_from_crane[static_cast<std::size_t>(3 * r + c)] = m.task_from_base(c, r);
    }
  }
  return info;
}

}  // namespace craneassist::cli
