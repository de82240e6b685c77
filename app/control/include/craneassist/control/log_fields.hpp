// The field table: every per-cycle value that leaves the controller, declared once (name, unit,
// meaning, where it comes from, its group, its CSV columns and its DDS member). The CSV log, the
// DDS telemetry frame, echo, the Foxglove channels and the MCAP recording are driven by it:
// a value added here (with its LogRow member and the line that fills it) reaches all of them.
// docs/log-format.md and docs/telemetry.md list it (`craneassist fields --markdown`).
//
// visit_fields(row, visitor) calls visitor(const Field&, member&) for each field in table order
// (the CSV's column order). A member is a double, a bool, an int, a long, a static string
// (const char*), or a std::array<double, N>: per joint (Field::per_joint, the first dof of
// LogRow::kMaxJoints) or a fixed vector whose components Field::components names.
#pragma once

#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "craneassist/control/csv_log.hpp"

namespace craneassist::control {

// The Foxglove/MCAP JSON channel a field is published on (/craneassist/<group>).
enum class FieldGroup {
  kStatus,
  kCommand,
  kJoints,
  kHydraulics,
  kLimits,
  kPolytope,
  kLoads,
  kBase
};
inline constexpr FieldGroup kFieldGroups[] = {
    FieldGroup::kStatus, FieldGroup::kCommand,  FieldGroup::kJoints, FieldGroup::kHydraulics,
    FieldGroup::kLimits, FieldGroup::kPolytope, FieldGroup::kLoads,  FieldGroup::kBase};
const char* to_string(FieldGroup group) noexcept;

struct Field {
  const char* name;     // the JSON key and the DDS field name (snake_case, SI unit suffix)
  const char* unit;     // SI: "m", "rad or m" (per joint), "1" (a ratio), "text", "bool", ...
  const char* source;   // input, controller, measured, simulator, loop, model
  const char* meaning;  // one sentence
  FieldGroup group;
  // The CSV log: nullptr, not written; a scalar's column; a vector's columns, comma-separated; a
  // per-joint pattern with '#' for the joint number 1..n ("q#_ref").
  const char* csv = nullptr;
  // printf format of one value (doubles); a fixed vector's may list one per component.
  const char* csv_format = "%.6g";
  double csv_scale = 1.0;         // the CSV holds value * csv_scale (the swing in degrees)
  bool csv_empty_if_nan = false;  // a NaN is an empty cell (not "nan")
  // The member of craneassist_msgs.idl that carries the value ("Status.scale"); nullptr: the
  // generic craneassist/fields topic only (every numeric field is there as well).
  const char* dds = nullptr;
  bool per_joint = false;            // a std::array<double, kMaxJoints>: the first dof
  const char* components = nullptr;  // a fixed vector's component names ("x,y,z")
  bool base_only = false;            // only with a wheeled base (sim --drive)
};

namespace field_detail {
inline constexpr const char* kXyz = "x,y,z";
}  // namespace field_detail

template <class Row, class Visitor>
void visit_fields(Row& r, Visitor&& v) {
  using G = FieldGroup;
  using field_detail::kXyz;
  // clang-format off
  v(Field{"t", "s", "loop", "machine time of the cycle since the start", G::kStatus, "t", "%.4f", 1.0, false, "Header.t_s"}, r.t);
  v(Field{"cmd", "m/s", "input", "commanded tip velocity (crane frame: x forward, y up, z lateral); NaN while the input is not valid", G::kCommand, "cmd_vx,cmd_vy,cmd_vz", "%.6g", 1.0, false, "CommandPath.command_m_s", false, kXyz}, r.cmd);
  v(Field{"ref_v", "m/s", "controller", "reference tip velocity after redundancy resolution and scaling, parallel to the command", G::kCommand, "ref_vx,ref_vy,ref_vz", "%.6g", 1.0, false, "CommandPath.reference_m_s", false, kXyz}, r.ref_v);
  v(Field{"tip", "m", "measured", "tip position from the measured joints (forward kinematics), crane frame", G::kJoints, "tip_x,tip_y,tip_z", "%.6f", 1.0, false, "JointState.tip_m", false, kXyz}, r.tip);
  v(Field{"tip_v", "m/s", "measured", "tip velocity J(q) qdot from the measured joints and rates, crane frame", G::kJoints, "tip_vx,tip_vy,tip_vz", "%.6g", 1.0, false, "JointState.tip_v_m_s", false, kXyz}, r.tip_v);
  v(Field{"q", "rad or m", "measured", "joint positions (revolute in rad, prismatic in m)", G::kJoints, "q#", "%.7f", 1.0, false, "JointState.q", true}, r.q);
  v(Field{"q_ref", "rad or m", "controller", "joint position references (the controller's integrated state)", G::kJoints, "q#_ref", "%.7f", 1.0, false, "JointState.q_ref", true}, r.q_ref);
  v(Field{"pump_flow_m3s", "m^3/s", "measured", "pump outlet flow", G::kHydraulics, "pump_flow_m3s", "%.6g", 1.0, false, "Hydraulics.flow_m3_s"}, r.pump_flow_m3s);
  v(Field{"pump_pressure_pa", "Pa", "measured", "pump supply pressure", G::kHydraulics, "pump_pressure_pa", "%.6g", 1.0, false, "Hydraulics.pressure_pa"}, r.pump_pressure_pa);
  v(Field{"pump_power_w", "W", "measured", "hydraulic power at the pump, pressure times flow", G::kHydraulics, "pump_power_w", "%.6g", 1.0, false, "Hydraulics.power_w"}, r.pump_power_w);
  v(Field{"energy_j", "J", "measured", "pump energy integrated since the start", G::kHydraulics, "energy_j", "%.6g", 1.0, false, "Hydraulics.energy_j"}, r.energy_j);
  v(Field{"active_limit", "text", "controller", "which limit holds the motion back (none, flow, cylinder_speed, power, pressure, singularity, joint_limit, overload, stale_input, stop_request, ...)", G::kLimits, "active_limit", "%.6g", 1.0, false, "Status.active_limit"}, r.active_limit);
  v(Field{"scale", "1", "controller", "reference tip speed over commanded tip speed (1: unscaled)", G::kLimits, "scale", "%.6g", 1.0, false, "Status.scale"}, r.scale);
  v(Field{"flow_demand_m3s", "m^3/s", "controller", "pump flow the unscaled command would need", G::kHydraulics, "flow_demand_m3s", "%.6g", 1.0, false, "Hydraulics.flow_demand_m3_s"}, r.flow_demand_m3s);
  v(Field{"pump_limit", "text", "measured", "which pump limit holds the delivered flow below demand: none, max_flow, power, relief", G::kHydraulics, "pump_limit", "%.6g", 1.0, false, "Hydraulics.pump_limit"}, r.pump_limit);
  v(Field{"s", "m", "controller", "path coordinate: tip arc length along the commanded directions", G::kCommand, "s", "%.6f", 1.0, false, "CommandPath.s"}, r.s);
  v(Field{"sdot", "m/s", "controller", "path speed after the scaling filter", G::kCommand, "sdot", "%.6g", 1.0, false, "CommandPath.sdot"}, r.sdot);
  v(Field{"sddot", "m/s^2", "controller", "path acceleration after the scaling filter", G::kCommand, "sddot", "%.6g", 1.0, false, "CommandPath.sddot"}, r.sddot);
  v(Field{"sdddot", "m/s^3", "controller", "path jerk after the scaling filter", G::kCommand, "sdddot", "%.6g", 1.0, false, "CommandPath.sdddot"}, r.sdddot);
  v(Field{"sddot_min", "m/s^2", "controller", "lower acceleration bound of this cycle (power, cylinder accelerations, path limits)", G::kLimits, "sddot_min", "%.6g", 1.0, false, "CommandPath.sddot_min"}, r.sddot_min);
  v(Field{"sddot_max", "m/s^2", "controller", "upper acceleration bound of this cycle", G::kLimits, "sddot_max", "%.6g", 1.0, false, "CommandPath.sddot_max"}, r.sddot_max);
  v(Field{"tip_error_m", "m", "controller", "filtered distance between the measured tip and the delayed reference", G::kCommand, "tip_error_m", "%.6g", 1.0, false, "Status.tip_error_m"}, r.tip_error_m);
  v(Field{"ref_power_w", "W", "controller", "pump power the dynamics model predicts for the reference", G::kHydraulics, "ref_power_w", "%.6g", 1.0, false, "Hydraulics.ref_power_w"}, r.ref_power_w);
  v(Field{"avail_speed_m_s", "m/s", "controller", "fastest tip speed the cylinders and the pump allow along the stick's direction, over every joint motion (flow manipulability polytope)", G::kPolytope, "avail_speed_m_s", "%.6g", 1.0, false, "Status.avail_speed_m_s"}, r.avail_speed_m_s);
  v(Field{"avail_speed_resolved_m_s", "m/s", "controller", "the same along the joint motion the controller chose", G::kPolytope, "avail_speed_resolved_m_s", "%.6g", 1.0, false, "Status.avail_speed_resolved_m_s"}, r.avail_speed_resolved_m_s);
  v(Field{"polytope_volume_m3s3", "m^3/s^3", "controller", "volume of the flow manipulability polytope at the reference pose (0 when flat)", G::kPolytope, "polytope_volume_m3s3", "%.6g", 1.0, false, "Status.polytope_volume_m3_s3"}, r.polytope_volume_m3s3);
  v(Field{"spool", "1", "controller", "valve command per section, -1 (full retract) .. 0 (neutral) .. +1 (full extend)", G::kJoints, "spool#", "%.5f", 1.0, false, "JointState.spool", true}, r.spool);
  v(Field{"load_pressure_pa", "Pa", "measured", "load pressure per cylinder, positive for a resistive load", G::kJoints, "p_load#_pa", "%.6g", 1.0, false, "JointState.load_pressure_pa", true}, r.load_pressure);
  v(Field{"load_kg", "kg", "simulator", "the mass in the simulated grapple (the truth the crane scale is measured against); NaN on a machine", G::kLoads, "load_kg", "%.6g", 1.0, true, "Status.load_truth_kg"}, r.load_kg);
  v(Field{"payload_estimate_kg", "kg", "controller", "the crane scale's estimate of the load from the chamber pressures", G::kLoads, "payload_estimate_kg", "%.6g", 1.0, false, "Status.payload_estimate_kg"}, r.payload_estimate_kg);
  v(Field{"load_moment_ratio", "1", "controller", "the estimate over the load chart's rated load at the reach (1: the rated load moment; 0: no chart)", G::kLoads, "load_moment_ratio", "%.6g", 1.0, false, "Status.load_moment_ratio"}, r.load_moment_ratio);
  v(Field{"status", "text", "controller", "running, stopping (a stop in progress) or stopped (every valve neutral)", G::kStatus, "status", "%.6g", 1.0, false, "Status.state"}, r.status);
  v(Field{"swing_rad", "rad", "simulator", "the hanging grapple's swing from the vertical (the CSV in degrees); NaN where nothing measures it", G::kLoads, "swing_deg", "%.4f", 180.0 / M_PI, true, "Status.swing_rad"}, r.swing_rad);
  v(Field{"swing_radial_rad", "rad", "simulator", "the swing towards the reach (positive: the grapple further out than the tip)", G::kLoads, "swing_radial_deg", "%.4f", 180.0 / M_PI, true, "Status.swing_radial_rad"}, r.swing_radial_rad);
  v(Field{"swing_tangential_rad", "rad", "simulator", "the swing across the reach (positive towards a positive slew)", G::kLoads, "swing_tangential_deg", "%.4f", 180.0 / M_PI, true, "Status.swing_tangential_rad"}, r.swing_tangential_rad);
  v(Field{"base_pose", "m, m, rad", "measured", "the chassis centre's position and heading in the world", G::kBase, "base_x,base_y,base_phi", "%.6f,%.6f,%.7f", 1.0, false, "BaseState.pose", false, "x,y,phi", true}, r.base_pose);
  v(Field{"base_velocity", "m/s, rad/s", "measured", "forward speed and yaw rate of the base", G::kBase, "base_v,base_omega", "%.6g", 1.0, false, "BaseState.velocity", false, "v,omega", true}, r.base_velocity);
  v(Field{"base_command", "m/s, rad/s", "controller", "the drive command, flow-bounded", G::kBase, "base_v_cmd,base_omega_cmd", "%.6g", 1.0, false, "BaseState.command", false, "v,omega", true}, r.base_command);
  v(Field{"base_motor_flow_m3s", "m^3/s", "measured", "each hub motor's flow (front left, front right, rear left, rear right)", G::kBase, "base_flow_fl_m3s,base_flow_fr_m3s,base_flow_rl_m3s,base_flow_rr_m3s", "%.6g", 1.0, false, "BaseState.motor_flow_m3_s", false, "fl,fr,rl,rr", true}, r.base_motor_flow);
  v(Field{"base_flow_sum_m3s", "m^3/s", "measured", "the hub motors' summed flow", G::kBase, "base_flow_sum_m3s", "%.6g", 1.0, false, "BaseState.motor_flow_sum_m3_s", false, nullptr, true}, r.base_flow_sum_m3s);
  v(Field{"base_flow_max_m3s", "m^3/s", "model", "the drive pump's maximum flow Q_max", G::kBase, "base_flow_max_m3s", "%.6g", 1.0, false, "BaseState.drive_max_flow_m3_s", false, nullptr, true}, r.base_flow_max_m3s);
  // Not in the CSV: the live view's and telemetry's values.
  v(Field{"qdot", "rad/s or m/s", "measured", "joint rates", G::kJoints, nullptr, "%.6g", 1.0, false, "JointState.qdot", true}, r.qdot);
  v(Field{"cylinder_pos_m", "m", "measured", "cylinder lengths", G::kJoints, nullptr, "%.6g", 1.0, false, "JointState.cylinder_pos_m", true}, r.cylinder_pos);
  v(Field{"cylinder_vel_m_s", "m/s", "measured", "cylinder velocities", G::kJoints, nullptr, "%.6g", 1.0, false, "JointState.cylinder_vel_m_s", true}, r.cylinder_vel);
  v(Field{"hanger_rad", "rad", "measured", "the URDF's hanger joints (hanger_across, hanger_along) that draw the grapple where the swing has it", G::kJoints, nullptr, "%.6g", 1.0, false, nullptr, false, "across,along"}, r.hanger_rad);
  v(Field{"hanger_rate_rad_s", "rad/s", "measured", "the hanger joints' rates", G::kJoints, nullptr, "%.6g", 1.0, false, nullptr, false, "across,along"}, r.hanger_rate_rad_s);
  v(Field{"flow_limit_m3s", "m^3/s", "model", "the pump's maximum flow, the limit pump_flow_m3s is held to", G::kHydraulics, nullptr, "%.6g", 1.0, false, "Hydraulics.flow_limit_m3_s"}, r.flow_limit_m3s);
  v(Field{"power_limit_w", "W", "model", "the prime mover's power, the limit pump_power_w is held to", G::kHydraulics, nullptr, "%.6g", 1.0, false, "Hydraulics.power_limit_w"}, r.power_limit_w);
  v(Field{"rated_load_kg", "kg", "model", "the load chart's rated load at the present reach (0: no chart)", G::kLoads, nullptr, "%.6g", 1.0, false, "Status.rated_load_kg"}, r.rated_load_kg);
  v(Field{"load_reach_m", "m", "measured", "the tip's horizontal distance from the slew axis", G::kLoads, nullptr, "%.6g", 1.0, false, "Status.load_reach_m"}, r.load_reach_m);
  v(Field{"payload_converged", "bool", "controller", "the crane scale has converged (until then the dynamics assume the chart's rated load)", G::kLoads, nullptr, "%.6g", 1.0, false, "Status.payload_converged"}, r.payload_converged);
  v(Field{"load_warning", "bool", "controller", "the load moment is at 90 % of the chart or more", G::kLoads, nullptr, "%.6g", 1.0, false, "Status.load_warning"}, r.load_warning);
  v(Field{"load_overload", "bool", "controller", "the rated capacity limiter has tripped: motions that raise the load moment stop", G::kLoads, nullptr, "%.6g", 1.0, false, "Status.overload"}, r.load_overload);
  v(Field{"polytope_dim", "1", "controller", "the polytope's dimension: 3 a solid, 2 flat (a planar arm or a singular pose), 1, 0", G::kPolytope, nullptr, "%.6g", 1.0, false, "Status.polytope_dim"}, r.polytope_dim);
  v(Field{"polytope_area_m2s2", "m^2/s^2", "controller", "the polytope's area in its plane when flat (polytope_dim 2)", G::kPolytope, nullptr, "%.6g", 1.0, false, "Status.polytope_area_m2_s2"}, r.polytope_area_m2s2);
  v(Field{"stop_reason", "text", "loop", "why the crane stops or holds (empty while running)", G::kStatus, nullptr, "%.6g", 1.0, false, "Status.stop_reason"}, r.stop_reason);
  v(Field{"input_source", "text", "input", "where the command comes from: keyboard, evdev, sdl, dds, web, replay", G::kStatus, nullptr, "%.6g", 1.0, false, "Status.input_source"}, r.input_source);
  v(Field{"deadman", "bool", "input", "the operator's enable is held", G::kStatus, nullptr, "%.6g", 1.0, false, "Status.deadman"}, r.deadman);
  v(Field{"loop_latency_max_s", "s", "loop", "worst start latency of the loop's cycles so far (0: not paced)", G::kStatus, nullptr, "%.6g", 1.0, false, "Status.loop_latency_max_s"}, r.loop_latency_max_s);
  v(Field{"loop_compute_s", "s", "loop", "compute time of the previous cycle", G::kStatus, nullptr, "%.6g", 1.0, false, "Status.loop_compute_s"}, r.loop_compute_s);
  v(Field{"loop_overruns", "1", "loop", "cycles whose work ended after the next tick, so far", G::kStatus, nullptr, "%.6g", 1.0, false, "Status.loop_overruns"}, r.loop_overruns);
  v(Field{"base_present", "bool", "measured", "the crane stands on a wheeled base (sim --drive)", G::kBase, nullptr, "%.6g", 1.0, false, nullptr, false, nullptr, true}, r.base_present);
  v(Field{"base_shared_pump", "bool", "model", "the crane's pump flow counts against the drive pump's Q_max", G::kBase, nullptr, "%.6g", 1.0, false, "BaseState.shared_pump", false, nullptr, true}, r.base_shared_pump);
  // clang-format on
}

// The k-th item of a list ("x,y,z"; "m, m, rad" with separator ", "); the last one when the
// list has fewer (a single item serves every k).
std::string_view list_item(std::string_view list, std::size_t k, std::string_view separator = ",");

// Appends text as a JSON string: quotes, backslashes and control characters escaped.
void append_json_string(std::string_view text, std::string& out);

// The table, in order (for descriptions: docs, schemas, tests).
std::vector<Field> field_table();

// The CSV header for a crane with `dof` joints (with the base's columns when `base`).
std::string csv_header(int dof, bool base);

// The fields of `group` of one row as a JSON object (NaN as null; per-joint fields as arrays of
// dof numbers; vectors as objects of their components). Appends to `out`.
void append_group_json(const LogRow& row, int dof, FieldGroup group, std::string& out);
// Its JSON Schema (draft 2020-12), with each field's unit and meaning as its description.
std::string group_json_schema(FieldGroup group);

// Every numeric field (numbers, bools as 0/1; per-joint fields as dof values, vectors by
// component) flattened: the names ("q.1", "tip.x", ...) with their units and, for one row, the
// values. For the generic craneassist/fields DDS topic.
struct FlatField {
  std::string name;
  std::string unit;
};
std::vector<FlatField> flat_fields(int dof, bool base);
// Writes the values in flat_fields' order into out[0..]; returns how many (at most `size`).
int flat_field_values(const LogRow& row, int dof, bool base, double* out, int size) noexcept;

// The table as Markdown (docs/log-format.md, docs/telemetry.md): `craneassist fields --markdown`.
std::string fields_markdown();

}  // namespace craneassist::control
