// The Modular Hydraulic Servo Booster circuit, quasi-statically (paper 001 sections 1, 2.1, 2.2;
// docs/mhsb.md): its modes, what a servo-valve lets a cylinder do from a given supply pressure,
// which modes a load calls for, the admissible joint velocities of a mode pattern (the input of
// the flow manipulability polytope, flow_polytope.hpp) and the power an actuator draws.
//
// Cylinder conventions as in model.hpp: A1 = area_a_m2 (piston side), A2 = area_b_m2 (rod side);
// the force F (N) is the force the cylinder must exert along its extension to hold or move the
// load (positive: the load pushes the rod in). v > 0 extends.
//
// Servo-valve at full opening, each metering edge Q = K sqrt(dp) with K = Q_R / sqrt(P_R): with
// supply P_s and tank P_t, extending needs A1 v = K sqrt(P_s - P_1) and A2 v = K sqrt(P_2 - P_t),
// and F = A1 P_1 - A2 P_2, so (paper 001 eq. 2, divided by the area)
//     v_ext = K sqrt((A1 P_s - F - A2 P_t) / (A1^3 + A2^3)),
//     v_ret = K sqrt((A2 P_s + F - A1 P_t) / (A1^3 + A2^3)),
// 0 where the root's argument is negative (the supply cannot move the load that way). Turned
// round, the supply pressure that moves F at v:
//     P_s = (F + A2 P_t + (A1^3 + A2^3) v^2 / K^2) / A1   (v >= 0),
//     P_s = (-F + A1 P_t + (A1^3 + A2^3) v^2 / K^2) / A2  (v < 0).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "craneassist/dynamics/flow_polytope.hpp"
#include "craneassist/dynamics/model.hpp"

namespace craneassist::mhsb {

using dynamics::CraneModel;
using dynamics::Cylinder;
using dynamics::FlowPolytopeSettings;
using dynamics::JointVector;
using dynamics::JointVelocitySet;
using dynamics::kMaxJoints;
using dynamics::Mhsb;
using dynamics::ServoValve;

// N: the main pump alone at P0. DB: one servo-pump in series (pressure up to P0 + max_boost, flow
// at most one servo-pump's). SB: two servo-pumps' flows summed into the actuator.
enum class MhsbMode : std::uint8_t { kNormal, kDecoupledBoost, kSharedBoost };
inline constexpr std::array kMhsbModes{MhsbMode::kNormal, MhsbMode::kDecoupledBoost,
                                       MhsbMode::kSharedBoost};
// "N", "DB", "SB".
const char* to_string(MhsbMode mode);
std::optional<MhsbMode> parse_mhsb_mode(std::string_view text);
// Boost modules a mode takes: 0, 1, 2.
int modules_used(MhsbMode mode);
inline bool is_boost(MhsbMode mode) {
  return mode != MhsbMode::kNormal;
}

// One mode per joint.
struct ModePattern {
  std::array<MhsbMode, kMaxJoints> mode{};  // joints beyond dof are kNormal
  int dof = 0;

  int modules() const;
  // Joints whose mode differs from `other` (the planner's switching count G).
  int switches_from(const ModePattern& other) const;
  bool operator==(const ModePattern& other) const = default;
};
// "N-DB-SB" (one name per joint); parse_mode_pattern reads it back (nullopt: malformed or the
// wrong number of joints).
std::string to_string(const ModePattern& pattern);
std::optional<ModePattern> parse_mode_pattern(std::string_view text, int dof);

// Every pattern of `dof` joints that takes at most `modules` modules, all-N first, then in
// lexicographic order (joint 1 slowest). Three joints and four modules: 23 (paper 001 section 3).
std::vector<ModePattern> mode_patterns(int dof, int modules);

// Full-opening servo-valve speeds (>= 0) of a cylinder from supply P_s against F.
struct CylinderSpeeds {
  double extend_m_s = 0.0;
  double retract_m_s = 0.0;
};
CylinderSpeeds servo_valve_speeds(const Cylinder& cylinder, const ServoValve& valve,
                                  double supply_pa, double tank_pa, double force_n);

// The supply pressure that moves the cylinder at v against F through the fully open valve.
double required_supply_pressure_pa(const Cylinder& cylinder, const ServoValve& valve,
                                   double tank_pa, double force_n, double v_m_s);

// A positive (resistive) load: the force opposes the motion (F v > 0). A negative (over-running)
// load is braked by throttling the valve and never needs a boost.
inline bool positive_load(double force_n, double v_m_s) {
  return force_n * v_m_s > 0.0;
}

// The supply pressure a mode can give: P0 in N, P0 + max_boost (at most the relief setting) in DB
// and SB.
double mode_supply_pressure_pa(const CraneModel& model, MhsbMode mode);
// The flow a mode can give one actuator: unbounded in N (the main pump's sum limit applies), one
// servo-pump's in DB, two in SB.
double mode_flow_cap_m3_s(const Mhsb& mhsb, MhsbMode mode);

// Whether joint's cylinder, moving at v against F, needs more than P0 from its fully open valve:
// only a positive load can (false without model.mhsb).
bool needs_boost(const CraneModel& model, int joint, double force_n, double v_m_s);
// The modes a joint may take for a motion at v against F (paper 001 section 2.2): N when no boost
// is needed or the load is negative; DB and SB only when a positive load needs more than P0.
bool mode_allowed(const CraneModel& model, int joint, MhsbMode mode, double force_n, double v_m_s);

// The admissible joint velocities at q in a mode pattern (paper 001 eqs. 1, 3, 4): the box of
// joint_velocity_set() (cylinder speed limits, joint ends) cut, per direction, to what the joint's
// servo-valve delivers from its mode's supply against its cylinder force, and in DB/SB to the
// servo-pumps' flow; the main pump's flow limit on the sum of all actuators' flows (the
// servo-pumps are in series with it). cylinder_force_n: each cylinder's force at q (e.g. the
// gravity load, rigid_body_terms.hpp). Needs model.mhsb. No allocation.
void mhsb_joint_velocity_set(const CraneModel& model, const JointVector& q,
                             const JointVector& dc_dq, const JointVector& cylinder_force_n,
                             const ModePattern& pattern, const FlowPolytopeSettings& settings,
                             JointVelocitySet& out);

// How the power of a boosted actuator is counted.
enum class MhsbEnergyModel {
  // The circuit as built: the main pump delivers the actuator's flow (and its valve's leakage) at
  // P0, the servo-pump adds (P_s - P0) to it at its efficiency: (P0 + (P_s - P0) / eta) Q.
  kSeries,
  // Paper 001 eq. 9 as printed: P_s Q / eta + P_s Q_leak for a boosted actuator.
  kPaper,
};
inline constexpr std::array kMhsbEnergyModels{MhsbEnergyModel::kSeries, MhsbEnergyModel::kPaper};
const char* to_string(MhsbEnergyModel model);  // "series", "paper"
std::optional<MhsbEnergyModel> parse_mhsb_energy_model(std::string_view text);

// The power (W) one actuator draws moving at v against F in `mode`, its valve's leakage included.
// N: P0 (Q + Q_leak), whatever the load (the valve throttles the difference). Boost: the supply is
// held at the required pressure (at least P0), counted per `energy_model`. Q = A |v| with the
// area the flow fills (flow_area_m2).
double mhsb_actuator_power_w(const CraneModel& model, int joint, MhsbMode mode, double force_n,
                             double v_m_s, MhsbEnergyModel energy_model);

}  // namespace craneassist::mhsb
