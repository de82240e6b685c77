// The immutable crane model: kinematics, cylinder geometry, masses and hydraulics.
//
// Like Pinocchio's Model, it is built once (from config/) and then only read; every algorithm
// keeps its per-evaluation buffers in its own Data struct. All values are SI.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "craneassist/dynamics/enum_names.hpp"

namespace craneassist::dynamics {

// Upper bound on the number of joints: vectors are Eigen's bounded-dynamic type, so they live on
// the stack and a control cycle never allocates.
inline constexpr int kMaxJoints = 6;

using JointVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxJoints, 1>;
using JointMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxJoints, kMaxJoints>;
using TaskJacobian = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxJoints>;

enum class JointType { kRevolute, kPrismatic };

// Classical Denavit-Hartenberg row. Revolute: theta = q + theta_offset, d fixed.
// Prismatic: d = d_offset + q, theta fixed.
struct DhJoint {
  std::string name;
  JointType type = JointType::kRevolute;
  double a_m = 0.0;
  double alpha_rad = 0.0;
  double d_m = 0.0;
  double theta_rad = 0.0;
  double q_min = 0.0;  // rad or m
  double q_max = 0.0;
};

// A rigid body moving with DH frame `frame` (1..n). Centre of mass and inertia (about the centre
// of mass) are given in that frame's axes.
struct Body {
  std::string name;
  int frame = 0;
  double mass_kg = 0.0;
  Eigen::Vector3d com_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d inertia_diag_kgm2 = Eigen::Vector3d::Zero();
};

// How a joint coordinate maps to its cylinder length c(q) and torque arm dc/dq.
enum class LinkageType {
  kConstantArm,  // c = c0 + arm * q (rack and pinion, telescope multiplier, rotary actuator)
  kTriangle,     // c = sqrt(l1^2 + l2^2 - 2 l1 l2 cos(q + angle_offset)) (lift cylinder)
  kPolynomial,   // c = sum coeffs[k] q^(N-k), highest power first (tilt four-bar fit)
};

// Friction of a cylinder's seals and guides (docs/loads.md): a Coulomb force against the motion,
// of its own size each way, and a viscous force growing with the speed. The simulator applies it
// (docs/simulator.md); the payload estimator subtracts it from the pressure force while a cylinder
// moves. Zero: none.
struct CylinderFriction {
  double coulomb_extend_n = 0.0;   // while extending
  double coulomb_retract_n = 0.0;  // while retracting
  double viscous_n_s_m = 0.0;      // per m/s of cylinder speed
};

// The friction force at cylinder speed v (N, along v: the motion pays it), the Coulomb part
// turning from one direction to the other over about sign_speed_m_s (tanh). The simulator and the
// payload estimator each use it with their own sign_speed.
inline double friction_force_n(const CylinderFriction& f, double v_m_s, double sign_speed_m_s) {
  const double coulomb = v_m_s >= 0.0 ? f.coulomb_extend_n : f.coulomb_retract_n;
  return coulomb * std::tanh(v_m_s / sign_speed_m_s) + f.viscous_n_s_m * v_m_s;
}

struct Cylinder {
  std::string name;
  LinkageType linkage = LinkageType::kConstantArm;
  double arm_m = 0.0;               // kConstantArm: dc/dq (m/rad or m/m)
  double c0_m = 0.0;                // kConstantArm: c at q = 0
  double l1_m = 0.0, l2_m = 0.0;    // kTriangle
  double angle_offset_rad = 0.0;    // kTriangle
  std::vector<double> poly_coeffs;  // kPolynomial, highest power first
  double area_a_m2 = 0.0;           // piston side
  double area_b_m2 = 0.0;           // rod side
  bool differential_spool = false;  // extension: pump supplies A_A - A_B when extending
  double stroke_m = 0.0;
  double v_max_m_s = 0.0;
  double a_max_m_s2 = 0.0;
  CylinderFriction friction;
};

// How the variable pump sets its supply pressure (paper 000 section 2.1, fig. 3).
enum class PumpMode {
  kLoadSensing,       // highest load pressure + ls_margin (standby_pressure when idle)
  kConstantPressure,  // held at supply_pressure whatever the loads
};
inline constexpr std::array kPumpModes{PumpMode::kLoadSensing, PumpMode::kConstantPressure};
// "load-sensing", "constant-pressure" (the config's hydraulics.pump.mode).
inline const char* to_string(PumpMode mode) {
  return mode == PumpMode::kConstantPressure ? "constant-pressure" : "load-sensing";
}
inline std::optional<PumpMode> parse_pump_mode(std::string_view text) {
  return parse_name(kPumpModes, text);
}

// The pump-power bound of the path scaling (docs/scaling.md): the config's scaling.power_bound
// and --power-bound. Beside PumpMode rather than in scaling/ because config, which must not
// depend on the scaling algorithms, reads it.
enum class PowerBound {
  kLoadSensing,       // the pump's power (default): LS, or p_s Q for a constant-pressure pump
  kActuatorPowerSum,  // the older sum-of-actuator-powers bound (baseline)
  kNone,              // no power limit
};
inline constexpr std::array kPowerBounds{PowerBound::kLoadSensing, PowerBound::kActuatorPowerSum,
                                         PowerBound::kNone};
// "load_sensing", "actuator_sum", "none".
inline const char* to_string(PowerBound bound) {
  switch (bound) {
    case PowerBound::kLoadSensing:
      return "load_sensing";
    case PowerBound::kActuatorPowerSum:
      return "actuator_sum";
    case PowerBound::kNone:
      return "none";
  }
  return "?";
}
inline std::optional<PowerBound> parse_power_bound(std::string_view text) {
  return parse_name(kPowerBounds, text);
}

struct Pump {
  PumpMode mode = PumpMode::kLoadSensing;
  double max_flow_m3_s = 0.0;
  double max_pressure_pa = 0.0;  // relief setting
  // Load-sensing margin; also the pressure compensators' margin dp_c in both modes.
  double ls_margin_pa = 0.0;
  double prime_mover_power_w = 0.0;
  double standby_pressure_pa = 0.0;  // LS supply pressure with no section open
  double supply_pressure_pa = 0.0;   // constant-pressure setpoint p_s; 0: not given
};

// Highest supply pressure the pump gives: the relief setting, or in constant-pressure mode the
// setpoint (capped by the relief).
inline double supply_pressure_ceiling_pa(const Pump& p) {
  return p.mode == PumpMode::kConstantPressure ? std::min(p.supply_pressure_pa, p.max_pressure_pa)
                                               : p.max_pressure_pa;
}

// Measured characteristic of one valve section (paper 000 appendix A): the steady cylinder
// velocity reached at each normalised spool command, both directions in one table, commands
// strictly increasing in [-1, 1], velocities non-decreasing (zero over the dead band, strictly
// increasing outside it). The command is the normalised spool command of ValveCommand; a valve
// driver (CAN) maps it to a current or a flow. Empty: the straight-line model of ValveSections.
struct ValveTable {
  std::vector<double> command;       // -1 .. 1
  std::vector<double> velocity_m_s;  // positive: extending
  // The section's own spool dynamics where measured (craneassist calibrate); NaN:
  // ValveSections' time_constant and delay.
  double time_constant_s = std::numeric_limits<double>::quiet_NaN();
  double delay_s = std::numeric_limits<double>::quiet_NaN();
  bool empty() const { return command.empty(); }
};

// The load-holding (counterbalance) valves on the cylinders that carry a load (docs/loads.md): a
// cylinder whose load the pump cannot move is held; a load pressure above the valve's port relief
// setting opens it, and the cylinder creeps in the load's direction at the valve's relief flow,
// never faster (the section's own lowering excepted). relief_pa 0: the pump's relief;
// relief_flow_m3_s 0 (no valves configured): nothing bounds a load beyond the relief.
struct LoadHolding {
  double relief_pa = 0.0;
  double relief_flow_m3_s = 0.0;
};

struct ValveSections {
  double dead_zone = 0.0;  // fraction of the spool (current) range with no flow
  double time_constant_s = 0.0;
  double delay_s = 0.0;
  // The spool command's slew-rate limit: the fastest a command may go from neutral to full
  // opening (0: no limit). Every command sent to the valves moves at most period / stroke_time
  // per cycle, as a valve driver's ramp would (docs/valves.md).
  double stroke_time_s = 0.0;
  // Optional measured characteristic per section (cylinder, same index); empty tables or an
  // empty vector: the straight line through dead_zone and the cylinder's max_speed.
  std::vector<ValveTable> tables;
};

// A four-way servo-valve in front of each cylinder (MHSB arms; paper 001 eqs. 1-2): at full
// opening each metering edge passes rated_flow at rated_pressure_drop (Q = Q_R sqrt(dp / P_R)),
// and the valve leaks `leakage` from supply to tank whatever its opening.
struct ServoValve {
  double rated_flow_m3_s = 0.0;
  double rated_pressure_drop_pa = 0.0;
  double leakage_m3_s = 0.0;
};

// The Modular Hydraulic Servo Booster circuit (paper 001 section 1; docs/mhsb.md). The main pump
// (CraneModel::pump, constant pressure P0 = supply_pressure) feeds every actuator's servo-valve;
// boost modules, each a servo-pump (an electric-motor-driven fixed pump) with a check valve and
// switching valves, can be put in series between the main pump and an actuator's valve:
//  - N (normal): no module; supply P0, the main pump's flow shared by all actuators;
//  - DB (decoupled boost): one module; supply up to P0 + max_boost, the actuator's flow at most
//    one servo-pump's servo_pump_max_flow;
//  - SB (shared boost): two modules' flows summed into one actuator (the reading of the paper that
//    gives its 23 mode patterns for three actuators and four modules, and its Table 2 speed limits:
//    DB 8.2/10.7 mm/s, SB the full 12 mm/s).
// The main pump also supplies what the servo-pumps deliver (they are in series with it).
struct Mhsb {
  int modules = 0;  // boost modules fitted
  double servo_pump_max_flow_m3_s = 0.0;
  double max_boost_pa = 0.0;  // highest pressure a servo-pump adds
  double servo_pump_efficiency = 1.0;
  double tank_pressure_pa = 0.0;
  // The planner's quasi-static cylinder speed limit V_L (paper 001 section 2.2, assumption 2).
  double velocity_limit_m_s = 0.0;
  ServoValve valve;
};

// The grapple and rotator hanging from the boom tip on a two-axis link (a universal joint whose
// pivot is the tip the operator steers; docs/sway.md), with the load in the grapple. Only the
// simulator swings it: the controller's dynamics carry the tip's bodies and the payload at the
// tip, which is where their weight acts at rest. com_below_m 0: nothing hangs (the bodies at the
// tip are rigid there).
struct HangingGrapple {
  double com_below_m = 0.0;        // pivot to the centre of mass of the bodies at the tip
  double load_below_m = 0.0;       // pivot to the load's centre in the grapple (a point mass)
  double damping_n_m_s_rad = 0.0;  // the link's brake or friction damping, each axis
  bool hangs() const { return com_below_m > 0.0; }
};

struct CraneModel {
  std::string name;
  std::vector<DhJoint> joints;      // n joints
  std::vector<Body> bodies;         // rigid bodies; the payload is one of them (at the tip)
  std::vector<Cylinder> cylinders;  // one per joint
  Eigen::Vector3d gravity_m_s2 = Eigen::Vector3d(0, 0, -9.81);  // in the DH base frame
  // Rows map base-frame coordinates to the crane (task) frame: x_crane = task_from_base * x_base.
  Eigen::Matrix3d task_from_base = Eigen::Matrix3d::Identity();
  Pump pump;
  ValveSections valves;
  LoadHolding load_holding;
  HangingGrapple grapple;
  // An MHSB circuit (hydraulics.mhsb); absent: valve sections on a load-sensing or
  // constant-pressure pump.
  std::optional<Mhsb> mhsb;

  int dof() const { return static_cast<int>(joints.size()); }
};

// The load-holding valves' port relief setting (the pump's relief when the model gives none).
inline double load_holding_relief_pa(const CraneModel& m) {
  return m.load_holding.relief_pa > 0.0 ? m.load_holding.relief_pa : m.pump.max_pressure_pa;
}

// The payload in the grapple is the body of this name (the config's payload.mass).
inline constexpr std::string_view kPayloadBody = "payload";
inline bool is_payload(const Body& b) {
  return b.name == kPayloadBody;
}

// The payload body's mass (0 when the model has none).
inline double payload_mass_kg(const CraneModel& m) {
  for (const Body& b : m.bodies) {
    if (is_payload(b)) return b.mass_kg;
  }
  return 0.0;
}

// Sets the payload body's mass (a model without one: nothing changes). No range check (config's
// set_payload_mass checks the config field's range). No allocation.
inline void set_payload_mass_kg(CraneModel& m, double mass_kg) {
  for (Body& b : m.bodies) {
    if (is_payload(b)) b.mass_kg = mass_kg;
  }
}

// Effective area the pump must fill for cylinder velocity v (docs/algorithms.md section 2).
inline double flow_area_m2(const Cylinder& c, double v_m_s) {
  if (v_m_s >= 0.0) return c.differential_spool ? c.area_a_m2 - c.area_b_m2 : c.area_a_m2;
  return c.area_b_m2;
}

}  // namespace craneassist::dynamics
