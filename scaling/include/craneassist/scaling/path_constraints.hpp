// Constraints on the path speed and acceleration of a joint path q = f(s), at the current
// (q, sdot): the velocity-level limits (pump flow, cylinder speeds, quasi-static power) and the
// acceleration-level bounds (load-sensing power, cylinder accelerations, path acceleration)
// that the jerk-bounded scaling filter then respects. docs/algorithms.md sections 2 and 4.
//
// With qdot = f' sdot and qddot = f'' sdot^2 + f' sddot, the joint efforts are
// tau = m sddot + b (dynamics::PathTerms), the cylinder velocities v_i = r_i f'_i sdot (r_i =
// dc_i/dq_i, signed), the cylinder forces F_i = tau_i / r_i, and the load pressures
// p_i = sign(v_i) F_i / Aflow_i (positive: resistive). A load-sensing pump then needs
//     P = (max_i p_i + dp_LS) * Q(sdot) <= P_max   and   max_i p_i + dp_LS <= p_relief,
// one linear inequality in sddot per moving cylinder ("Real-time trajectory scaling algorithm
// for hydraulic manipulators subject to limited on-board power", eqs. 11-12, in actuator space).
// The baseline bound of the same paper (eqs. 9-10, after Flores and Kecskemethy) limits the sum
// of actuator powers instead, |sdot f'^T (m sddot + b)| <= P_max; it is kept for comparison.
// With a constant-pressure pump (model.pump.mode) the kLoadSensing bound becomes that pump's own
// power, P = p_s Q(sdot) <= P_max (a speed limit), and max_i p_i + dp_c <= p_s (the sections
// keep their flow; paper 000 eq. 43).
#pragma once

#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/path_terms.hpp"
#include "craneassist/scaling/active_limit.hpp"

namespace craneassist::scaling {

using dynamics::JointVector;
// The pump-power bound (load sensing, the actuator power sum, none), with its names:
// dynamics/model.hpp.
using dynamics::PowerBound;

// The path geometry at the current configuration.
struct PathGeometry {
  JointVector f1;       // f'(s): joint velocity per unit path speed
  JointVector f2;       // f''(s)
  JointVector dc_dq;    // torque arms r_i at q
  JointVector d2c_dq2;  // their derivatives
};

struct SpeedLimits {
  double sdot_flow = 0.0;  // pump flow (with the reserve)
  double sdot_cylinder = 0.0;
  int cylinder = -1;               // the cylinder that sets sdot_cylinder
  double flow_per_speed_m3 = 0.0;  // Q(sdot) / sdot
};

// Velocity-level limits of docs/algorithms.md section 2 for the path tangent f'.
void path_speed_limits(const dynamics::CraneModel& model, const PathGeometry& path,
                       double flow_reserve, SpeedLimits& out);

struct AccelerationBounds {
  double sddot_min = 0.0;
  double sddot_max = 0.0;
  // What sets each side: kCylinderAcceleration, kPower (the prime mover's power), kPressure (a
  // load pressure at relief, or at p_s - dp_c with a constant-pressure pump), or kNone for the
  // path's own bound.
  ActiveLimit limit_min = ActiveLimit::kNone;
  ActiveLimit limit_max = ActiveLimit::kNone;
  // min(P_max / Q - dp_LS, p_relief - dp_LS) (LS bound); p_s - dp_c (constant pressure).
  double pressure_limit_pa = 0.0;
  // Highest path speed at which the power bound still admits sddot = 0 (quasi-static power
  // limit), evaluated with the loads of this cycle; +inf when power does not limit.
  double sdot_power = 0.0;
  ActiveLimit sdot_power_kind = ActiveLimit::kPower;  // kPressure: 0 for a load beyond relief
  // Highest path speed at which the curvature term of each cylinder's acceleration,
  // (r'_i f'_i^2 + r_i f''_i) sdot^2, stays within its limit with sddot = 0: where f' vanishes
  // (a turning point of the path) the acceleration bound becomes this speed bound.
  double sdot_acceleration = 0.0;
};

struct AccelerationLimits {
  double path_acceleration_max = 1.0;  // sddot <= this (the path itself)
  PowerBound power_bound = PowerBound::kLoadSensing;
  double power_reserve = 0.0;          // the bound uses P_max (1 - power_reserve)
  double path_deceleration_max = 1.0;  // sddot >= -this (the path itself)
};

// Intersection of the acceleration-level constraints at the current sdot (>= 0).
void path_acceleration_bounds(const dynamics::CraneModel& model, const PathGeometry& path,
                              const dynamics::PathTerms& terms, double sdot,
                              const AccelerationLimits& limits, AccelerationBounds& out);

// Load-sensing pump power of the path motion at (sdot, sddot), W: what a real LS pump would
// draw (max load pressure + margin) times flow. For tests and logs.
double load_sensing_power(const dynamics::CraneModel& model, const PathGeometry& path,
                          const dynamics::PathTerms& terms, double sdot, double sddot);

// The model's pump power at (sdot, sddot), W: load_sensing_power, or p_s Q for a
// constant-pressure pump (model.pump.mode).
double pump_power(const dynamics::CraneModel& model, const PathGeometry& path,
                  const dynamics::PathTerms& terms, double sdot, double sddot);

}  // namespace craneassist::scaling
