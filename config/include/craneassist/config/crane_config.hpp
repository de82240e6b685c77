// Loading and validating a crane configuration file (config/cranes/*.yaml, docs/config.md).
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "craneassist/config/config_error.hpp"
#include "craneassist/dynamics/enum_names.hpp"
#include "craneassist/dynamics/machine_deviation.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/resolutions.hpp"

namespace YAML {
class Node;
}

namespace craneassist::config {

struct ControlSettings {
  double rate_hz = 100.0;
  double position_gain_1_s = 0.0;  // P feedback on cylinder position error
  // Valve activation rule (paper 000 appendix A) when executing a planned trajectory: a section
  // stays closed while its cylinder velocity reference is below activation_speed and its position
  // error below activation_error. The planner counts such a cylinder as at rest. Zero: off.
  double activation_speed_m_s = 0.0;
  double activation_error_m = 0.0;
  // Fraction of the pump's maximum flow the prescaling leaves for the feedback corrections.
  double flow_reserve = 0.0;
  // A stop ends when the measured motion is at rest: the tip and every cylinder slower than
  // rest_speed for the valves' lag (delay plus time constant), or rest_timeout after the
  // reference came to rest, whichever is first; then the valves ramp to neutral (docs/safety.md).
  double rest_speed_m_s = 0.005;
  double rest_timeout_s = 2.0;
};

// The path scaling of the tip motion (docs/scaling.md).
struct ScalingSettings {
  double jerk_max_m_s3 = 4.0;                       // path jerk bound
  double acceleration_max_m_s2 = 1.0;               // path acceleration bound
  double deceleration_max_m_s2 = 1.0;               // path deceleration bound
  double direction_change_acceleration_m_s2 = 0.6;  // tip normal acceleration when turning
  double tracking_error_ok_m = 0.05;                // slow-down threshold e_ok
  double tracking_error_filter_s = 0.05;            // first-order filter on the tip error
  dynamics::PowerBound power_bound = dynamics::PowerBound::kLoadSensing;
  double power_reserve = 0.0;  // share of P_max kept for feedback corrections
  // Sway damping of the hanging grapple (docs/sway.md): the goal velocity input-shaped to the
  // pendulum (a crane whose grapple does not hang has nothing to damp).
  bool sway_damping = true;
  // The shaper's frequency: the model's (false), or the model's tuned to the swing the machine's
  // swing sensor measures (true, `sway_frequency: measured`; the model's until it has measured,
  // and on a machine without a sensor).
  bool sway_frequency_measured = true;
};

struct RedundancySettings {
  dynamics::Resolution resolution = dynamics::Resolution::kPinvJoint;
  // "energy-optimal": the resolution follows the pump mode (dynamics::energy_optimal_resolution);
  // call apply_energy_optimal after changing the pump mode.
  bool energy_optimal = false;
};

struct SimulationSettings {
  double step_s = 1e-3;
  dynamics::JointVector q_initial;
  // The simulated machine's chamber pressure sensors (docs/loads.md): white noise of this
  // standard deviation, then rounded to the resolution. Zero: exact.
  double pressure_noise_pa = 0.0;
  double pressure_resolution_pa = 0.0;
  // Pressure in the chamber that returns to tank.
  double return_pressure_pa = 0.0;
  // The simulated machine where it differs from the controller's model
  // (docs/valves.md#the-machine-it-meets): its valve sections by joint index (simulation.valves,
  // and the older simulation.spool_time_constant for every section's lag), its joint sensors
  // and feedback path (simulation.joint_sensors, simulation.feedback).
  dynamics::ValveDeviations valves{};
  dynamics::JointSensing joints{};
  // The simulated machine's swing sensor on the grapple's link (docs/sway.md): white noise of
  // this standard deviation on each of its two angles, then rounded to the resolution (zero:
  // exact); swing_sensor false (`swing_sensor: none`): the machine has none.
  bool swing_sensor = true;
  double swing_noise_rad = 0.0;
  double swing_resolution_rad = 0.0;
  // The simulated machine's grapple when it differs from the controller's model (`grapple`):
  // the model's values for those left out.
  std::optional<dynamics::HangingGrapple> grapple;
};

// Rated load against reach, the horizontal distance from the slew axis to the tip (EN 12999's
// load chart; docs/loads.md). Empty: no rated capacity limiter.
struct LoadChart {
  std::vector<double> reach_m;   // increasing
  std::vector<double> rated_kg;  // one per reach
  bool empty() const { return reach_m.empty(); }
  // Linear between the points; inside the first point the first value; beyond the last the last
  // point's load moment (rated * reach) held. No allocation.
  double rated_kg_at(double reach) const;
};

// Which machine the loop drives (`backend: sim | can`) and, for can, where it is.
enum class BackendKind { kSim, kCan };
inline constexpr std::array kBackendKinds{BackendKind::kSim, BackendKind::kCan};
const char* to_string(BackendKind kind);  // "sim", "can"
inline std::optional<BackendKind> parse_backend_kind(std::string_view text) {
  return parse_name(kBackendKinds, text);
}

struct CanSettings {
  std::string interface;  // can0, vcan0; empty: must be given on the command line
  // Signal mapping file (docs/can.md), resolved against the config file's folder; empty: the
  // embedded K70M mapping (config/can/k70m_can.yaml).
  std::string mapping;
  double feedback_timeout_s = 0.05;  // a joint's position older than this is lost feedback
};

struct BackendSettings {
  BackendKind kind = BackendKind::kSim;
  CanSettings can;
};

struct CraneConfig {
  dynamics::CraneModel model;
  ControlSettings control;
  ScalingSettings scaling;
  RedundancySettings redundancy;
  SimulationSettings simulation;
  BackendSettings backend;  // optional in the file: sim
  LoadChart load_chart;     // optional in the file
  std::string source_name;  // file the config came from, or "<embedded k70m.yaml>"
  // Number of quantities in the file that do not state where they come from.
  int unsourced_quantities = 0;
};

// Both throw ConfigError naming the file, line and field of the first problem found.
CraneConfig load_crane_config(const std::filesystem::path& path);
CraneConfig parse_crane_config(std::string_view yaml_text, std::string_view source_name);

// A machine variant (`craneassist suite --variants`, docs/valves.md#the-machine-it-meets): the
// simulated-machine fields of a crane config's simulation section (spool_time_constant, valves,
// joint_sensors, feedback) read from node and applied to cfg.simulation. Throws ConfigError
// naming source, the node's line and path plus the field.
void apply_simulated_machine(const YAML::Node& node, const std::string& source,
                             const std::string& path, CraneConfig& cfg);

// The shipped models, embedded in the binary (config/cranes/k70m.yaml, planar_2r.yaml).
CraneConfig default_crane_config();
CraneConfig planar_2r_config();
// The three-link MHSB arm of paper 001 (config/cranes/mhsb_3link.yaml; docs/mhsb.md).
CraneConfig mhsb_3link_config();

// With redundancy.energy_optimal, sets the resolution for the model's present pump mode.
void apply_energy_optimal(CraneConfig& cfg);

// The resolution name that picks the energy-optimal one for the pump mode
// (redundancy.energy_optimal).
inline constexpr std::string_view kEnergyOptimal = "energy-optimal";
// Every name set_resolution takes: energy-optimal, then the resolutions' own
// (dynamics::kResolutions).
std::vector<std::string> resolution_names();

// Sets the redundancy resolution from its name: one of resolution_names(). Throws
// std::invalid_argument for an unknown name, or a resolution other than pinv-joint on a model
// without the loader structure (slew, lift, tilt, extension).
void set_resolution(CraneConfig& cfg, std::string_view name);

// "min-ls-power (energy-optimal for load sensing)", "pinv-joint", ...
std::string resolution_description(const CraneConfig& cfg);

// The config fields the command line overrides (replay --payload, --pump-max-flow,
// --prime-mover-power, --supply-pressure, --can-feedback-timeout), checked against the same
// ranges as the file's fields (docs/config.md#ranges). Each throws std::invalid_argument with the
// reason, as the file's error gives it ("must be positive and at most 60000 L/min"), and then
// leaves the value unchanged.
void set_payload_mass(dynamics::CraneModel& model, double mass_kg);  // payload.mass
void set_pump_max_flow(dynamics::CraneModel& model, double m3_s);    // hydraulics.pump.max_flow
void set_prime_mover_power(dynamics::CraneModel& model, double w);   // ...prime_mover_power
void set_supply_pressure(dynamics::CraneModel& model, double pa);    // ...supply_pressure
void set_can_feedback_timeout(BackendSettings& backend, double seconds);  // can.feedback_timeout

// A joint pose written as "NAME=VALUE UNIT, ..." with the model's joint names, e.g.
// "lift=0 deg, tilt=-125 deg, extension=0.2 m" (angles in deg or rad, lengths in m, mm, cm).
// Joints left out keep their value in `base`. Throws std::invalid_argument naming the part that
// is wrong: an unknown joint, a joint given twice, a bad quantity, a value outside the range.
dynamics::JointVector parse_joint_pose(const dynamics::CraneModel& model, std::string_view text,
                                       const dynamics::JointVector& base);

}  // namespace craneassist::config
