// What the control loop hands to telemetry once per cycle: one plain, trivially copyable frame
// (no allocation, static strings only), and what stays fixed for a run. Plain C++17: no Fast DDS
// or Eigen types.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

namespace craneassist::dds {

inline constexpr int kMaxJoints = 8;
// The field table's numeric values a frame carries (craneassist/fields): 8 joints and a base
// need about 130.
inline constexpr int kMaxFieldValues = 192;

struct TelemetryFrame {
  std::uint64_t cycle = 0;
  double t_s = 0.0;           // machine time
  std::int64_t stamp_ns = 0;  // CLOCK_MONOTONIC at push() (set by the publisher)
  int dof = 0;
  std::array<double, kMaxJoints> q{}, q_ref{}, qdot{}, cylinder_pos_m{}, cylinder_vel_m_s{},
      load_pressure_pa{}, spool{};
  std::array<double, 3> tip_m{}, tip_v_m_s{}, command_m_s{}, reference_m_s{};
  double pump_flow_m3_s = 0.0, pump_pressure_pa = 0.0, pump_power_w = 0.0, energy_j = 0.0;
  double flow_demand_m3_s = 0.0, ref_power_w = 0.0;
  double scale = 0.0, s = 0.0, sdot = 0.0, sddot = 0.0, sdddot = 0.0, sddot_min = 0.0,
         sddot_max = 0.0, tip_error_m = 0.0;
  // Static strings only (string literals, to_string of enums): never freed.
  const char* status = "";
  const char* stop_reason = "";
  const char* active_limit = "";
  const char* pump_limit = "";
  const char* input_source = "";
  bool deadman = false;
  // Cycle timing: the worst start latency so far, the last compute time, overruns so far.
  double loop_latency_max_s = 0.0, loop_compute_s = 0.0;
  std::uint64_t loop_overruns = 0;
  // The flow manipulability polytope at the reference pose (ControllerOutput): the fastest tip
  // speed along the stick's direction (LP) and along the controller's joint motion, the
  // polytope's dimension, its volume (dimension 3) and its area when flat (dimension 2).
  double avail_speed_m_s = 0.0, avail_speed_resolved_m_s = 0.0;
  int polytope_dim = 0;
  double polytope_volume_m3_s3 = 0.0, polytope_area_m2_s2 = 0.0;
  // The load (docs/loads.md): the simulator's truth (NaN on a machine), the crane scale's
  // estimate and whether it has converged, the load moment against the chart, the chart's rated
  // load at the reach, the reach, the limiter's warning and trip.
  double load_truth_kg = 0.0, payload_estimate_kg = 0.0, load_moment_ratio = 0.0;
  double rated_load_kg = 0.0, load_reach_m = 0.0;
  bool payload_converged = false, load_warning = false, load_overload = false;
  // The hanging grapple's swing (docs/sway.md), rad: from the vertical, towards the reach, across
  // it; NaN where nothing measures it.
  double swing_rad = std::numeric_limits<double>::quiet_NaN();
  double swing_radial_rad = std::numeric_limits<double>::quiet_NaN();
  double swing_tangential_rad = std::numeric_limits<double>::quiet_NaN();
  // The URDF's hanger joints (TelemetryInfo::hanger_joint_names): angles, rad, and rates, rad/s.
  std::array<double, 2> hanger_rad{}, hanger_rate_rad_s{};
  // The wheeled base under the crane (sim --drive; topic craneassist/base): pose in the world
  // (x, y, heading), motion and drive command (forward speed, yaw rate), hub-motor flows (fl, fr,
  // rl, rr), their sum and the drive pump's Q_max. base_present false: a fixed base.
  bool base_present = false;
  bool base_shared_pump = false;
  std::array<double, 3> base_pose{};
  std::array<double, 2> base_velocity{}, base_command{};
  std::array<double, 4> base_motor_flow_m3_s{};
  double base_flow_sum_m3_s = 0.0, base_flow_max_m3_s = 0.0;
  // Every numeric value of the field table, in TelemetryInfo::field_names' order (the
  // craneassist/fields topic): value_count of them.
  std::array<double, kMaxFieldValues> values{};
  int value_count = 0;
};
static_assert(std::is_trivially_copyable_v<TelemetryFrame>);

// Fixed for a run: published in every sample where a dashboard needs it.
struct TelemetryInfo {
  std::string crane;    // model name
  std::string backend;  // sim, can
  std::string pump_mode;
  std::vector<std::string> joint_names;
  std::vector<bool> joint_prismatic;  // per joint: q in m (true) or rad (false)
  // The URDF's hanger joints of a hanging grapple (dynamics::kHangerJointNames; empty when
  // nothing hangs): /joint_states carries them after the crane's joints.
  std::vector<std::string> hanger_joint_names;
  double flow_limit_m3_s = 0.0;
  double power_limit_w = 0.0;
  // Maps a crane-frame vector (tip commands: x forward, y up, z lateral) to the DH base frame,
  // the URDF's base_link (the ROS 2 topics' frame). Row-major 3x3.
  std::array<double, 9> base_from_crane{1, 0, 0, 0, 1, 0, 0, 0, 1};
  // The names and units of TelemetryFrame::values (control::flat_fields).
  std::vector<std::string> field_names, field_units;
};

}  // namespace craneassist::dds
