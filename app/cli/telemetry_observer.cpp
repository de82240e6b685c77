#include "telemetry_observer.hpp"

#include <algorithm>

namespace craneassist::cli {

void to_frame(const control::LogRow& row, int dof, dds::TelemetryFrame& f) noexcept {
  const int n = std::min(dof, dds::kMaxJoints);
  f.t_s = row.t;
  f.dof = n;
  for (int i = 0; i < n; ++i) {
    const auto s = static_cast<std::size_t>(i);
    f.q[s] = row.q[s];
    f.q_ref[s] = row.q_ref[s];
    f.qdot[s] = row.qdot[s];
    f.cylinder_pos_m[s] = row.cylinder_pos[s];
    f.cylinder_vel_m_s[s] = row.cylinder_vel[s];
    f.load_pressure_pa[s] = row.load_pressure[s];
    f.spool[s] = row.spool[s];
  }
  f.tip_m = row.tip;
  f.tip_v_m_s = row.tip_v;
  f.command_m_s = row.cmd;
  f.reference_m_s = row.ref_v;
  f.pump_flow_m3_s = row.pump_flow_m3s;
  f.pump_pressure_pa = row.pump_pressure_pa;
  f.pump_power_w = row.pump_power_w;
  f.energy_j = row.energy_j;
  f.flow_demand_m3_s = row.flow_demand_m3s;
  f.ref_power_w = row.ref_power_w;
  f.scale = row.scale;
  f.s = row.s;
  f.sdot = row.sdot;
  f.sddot = row.sddot;
  f.sdddot = row.sdddot;
  f.sddot_min = row.sddot_min;
  f.sddot_max = row.sddot_max;
  f.tip_error_m = row.tip_error_m;
  f.status = row.status;
  f.stop_reason = row.stop_reason;
  f.active_limit = row.active_limit;
  f.pump_limit = row.pump_limit;
  f.input_source = row.input_source;
  f.deadman = row.deadman;
  f.loop_latency_max_s = row.loop_latency_max_s;
  f.loop_compute_s = row.loop_compute_s;
  f.loop_overruns = static_cast<std::uint64_t>(row.loop_overruns);
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
