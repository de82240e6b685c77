// Online redundancy resolutions of a loader crane parameterised by the extension rate
// (docs/algorithms.md section 7; "Global energy-optimal redundancy resolution of hydraulic
// manipulators: experimental results for a forestry manipulator", section 4).
//
// With the extension rate t = q4dot free, slew, lift and tilt follow from the tip velocity v:
// [q1dot q2dot q3dot] = [J1 J2 J3]^-1 (v - J4 t) (eq. 34), so every joint rate, and every
// cylinder velocity v_i = r_i qdot_i, is affine in t. Joint-rate bounds become one interval of t.
// Each resolution is a one-dimensional problem over that interval, solved exactly:
//   kPinvActuator: min sum v_i^2 (Beiner and Mattila): a quadratic, its minimiser clamped.
//   kMinFlow:      min pump flow Q = sum Aflow_i(sign v_i) |v_i| (the constant-pressure energy
//                  cost): convex piecewise linear, so the minimum is at a breakpoint (a cylinder
//                  at rest) or an end of the interval.
//   kMinLsPower:   min load-sensing power (max_i p_i + dp_LS) Q at the given cylinder forces:
//                  between breakpoints the moving set and the signs are fixed, so the power is
//                  linear there and the minimum again lies on a breakpoint or an end.
// The joint-limited pseudo-inverse (kPinvJoint) is the SNS of redundancy.hpp.
#pragma once

#include <array>
#include <optional>
#include <string_view>

#include "craneassist/dynamics/enum_names.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/redundancy.hpp"

namespace craneassist::dynamics {

enum class Resolution { kPinvJoint, kPinvActuator, kMinFlow, kMinLsPower };
inline constexpr std::array kResolutions{Resolution::kPinvJoint, Resolution::kPinvActuator,
                                         Resolution::kMinFlow, Resolution::kMinLsPower};
// "pinv-joint", "pinv-actuator", "min-flow", "min-ls-power".
const char* to_string(Resolution r);
inline std::optional<Resolution> parse_resolution(std::string_view text) {
  return parse_name(kResolutions, text);
}

// The energy-optimal online resolution for a pump: min-ls-power for a load-sensing pump (the
// pump's power follows the highest load pressure), min-flow for a constant-pressure pump (its
// power is p_s times the flow). Paper 000 sections 2.1, 4.
Resolution energy_optimal_resolution(PumpMode mode);

struct ExtensionResolutionInput {
  const TaskJacobian* jacobian = nullptr;  // tip Jacobian at q (loader structure)
  Eigen::Vector3d v_tip = Eigen::Vector3d::Zero();
  const JointVector* dc_dq = nullptr;           // torque arms at q
  const JointRateBounds* bounds = nullptr;      // joint-rate bounds
  const JointVector* cylinder_force = nullptr;  // kMinLsPower: forces at the current loads, N
};

struct ExtensionResolutionResult {
  JointVector qdot;
  double extension_rate = 0.0;  // the chosen t
  double cost = 0.0;            // the objective at t (m^2/s^2, m^3/s or W)
  bool feasible = false;        // false: no t meets every bound; qdot is then zero
};

// Solves the resolution (not kPinvJoint) exactly. Requires a loader-structure model
// (is_loader_structure). No allocation.
void resolve_by_extension(const CraneModel& model, Resolution resolution,
                          const ExtensionResolutionInput& in, ExtensionResolutionResult& out);

// The objective of a resolution at joint rates qdot (for tests and comparisons).
double resolution_cost(const CraneModel& model, Resolution resolution, const JointVector& qdot,
                       const JointVector& dc_dq, const JointVector* cylinder_force);

}  // namespace craneassist::dynamics
