// Synthetic telemetry for the tests of `craneassist echo` and `craneassist dashboard`: known
// values that the tests look for in the output (docs/dashboard.md's examples come from them).
#pragma once

#include <cstdint>

#include "craneassist/dds/telemetry_frame.hpp"

namespace craneassist::test {

inline constexpr double kTestPi = 3.14159265358979323846;
inline constexpr double kTestDt = 0.01;  // a 100 Hz loop

inline dds::TelemetryInfo test_telemetry_info() {
  dds::TelemetryInfo info;
  info.crane = "Test crane";
  info.backend = "sim";
  info.pump_mode = "load-sensing";
  info.joint_names = {"slew", "lift", "tilt", "extension"};
  info.joint_prismatic = {false, false, false, true};
  info.flow_limit_m3_s = 2e-3;  // 120 L/min
  info.power_limit_w = 35e3;
  return info;
}

// Cycle `cycle` of a crane holding still with the pump at 12.5 kW and 60 L/min, limited by
// power, the tip moving at 0.5 m/s in the command's direction, where the hydraulics allow
// 1.25 m/s.
inline dds::TelemetryFrame test_frame(std::uint64_t cycle) {
  dds::TelemetryFrame f;
  f.cycle = cycle;
  f.t_s = static_cast<double>(cycle) * kTestDt;
  f.dof = 4;
  const double deg = kTestPi / 180.0;
  f.q = {30.0 * deg, 20.0 * deg, -45.0 * deg, 1.25};
  f.q_ref = {30.5 * deg, 20.5 * deg, -44.5 * deg, 1.3};
  f.qdot = {0.1, -0.05, 0.02, 0.25};
  f.cylinder_pos_m = {0.5, 1.1, 0.9, 1.25};
  f.cylinder_vel_m_s = {0.01, -0.02, 0.03, 0.25};
  f.load_pressure_pa = {2e6, 12.5e6, 8e6, 3e6};
  f.spool = {0.1, -0.2, 0.3, 0.4};
  f.tip_m = {5.0, 2.5, -0.75};
  f.tip_v_m_s = {0.3, 0.4, 0.0};
  f.command_m_s = {0.375, 0.5, 0.0};
  f.reference_m_s = {0.3, 0.4, 0.0};
  f.pump_flow_m3_s = 1e-3;  // 60 L/min
  f.pump_pressure_pa = 12.5e6;
  f.pump_power_w = 12.5e3;
  f.energy_j = 12.5e3 * f.t_s;
  f.flow_demand_m3_s = 1.25e-3;
  f.ref_power_w = 13e3;
  f.scale = 0.8;
  f.s = 0.5 * f.t_s;
  f.sdot = 0.5;
  f.sddot_min = -2.0;
  f.sddot_max = 1.5;
  f.tip_error_m = 0.003;
  f.status = "running";
  f.stop_reason = "";
  f.active_limit = "power";
  f.pump_limit = "none";
  f.input_source = "replay";
  f.deadman = true;
  f.loop_latency_max_s = 120e-6;
  f.loop_compute_s = 40e-6;
  f.loop_overruns = 2;
  f.avail_speed_m_s = 1.25;  // the stick's 0.625 m/s is half of it
  f.avail_speed_resolved_m_s = 1.0;
  f.polytope_dim = 3;
  f.polytope_volume_m3_s3 = 51.51;
  f.load_truth_kg = 450.0;
  f.payload_estimate_kg = 448.5;
  f.payload_converged = true;
  f.load_moment_ratio = 0.5;
  f.rated_load_kg = 897.0;
  f.load_reach_m = 5.5;
  f.load_warning = false;
  f.load_overload = false;
  return f;
}

}  // namespace craneassist::test
