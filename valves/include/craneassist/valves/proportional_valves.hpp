// Cylinder velocity references to spool commands: the dead-zone inverse with optional P feedback
// on cylinder position, I = DZI(v_ref + Kp e) (paper 000 appendix A, docs/valves.md). DZI inverts
// the section's measured velocity-vs-command table (hydraulics.valves.tables, interpolated) when
// the model has one, otherwise the straight line through dead_zone and the cylinder's max_speed.
// Activation rule (same appendix): a section stays closed while its velocity reference is below
// eps_v and its position error below eps_p (both zero: the rule is off).
#pragma once

#include <array>

#include "craneassist/dynamics/model.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::valves {

struct ProportionalValvesInput {
  JointVector velocity_ref_m_s;  // cylinder velocity references
  JointVector position_error_m;  // cylinder position reference minus measurement
};

class ProportionalValves {
 public:
  ProportionalValves(const dynamics::CraneModel& model, double position_gain_1_s,
                     double activation_speed_m_s = 0.0, double activation_error_m = 0.0);

  // Spool commands in [-1, 1]; 0 for a reference below min_speed (stays in the dead zone).
  void update(const ProportionalValvesInput& in, ValveCommand& out) const;

  // Section i's DZI: the spool command for a steady cylinder velocity (its table, or the straight
  // line), and the edge of its dead band on one side (side > 0: extension; signed).
  double spool_for(int i, double velocity_m_s) const;
  double dead_band_edge(int i, double side) const;
  // The measured table of section i, or nullptr (straight line).
  const dynamics::ValveTable* table(int i) const { return tables_[static_cast<std::size_t>(i)]; }

  // The straight-line model: spool command to steady cylinder velocity, and its inverse.
  static double velocity_from_spool(double spool, double dead_zone, double v_max_m_s);
  static double spool_from_velocity(double velocity_m_s, double dead_zone, double v_max_m_s);

 private:
  const dynamics::CraneModel& model_;
  std::array<const dynamics::ValveTable*, dynamics::kMaxJoints> tables_{};
  double position_gain_1_s_;
  double activation_speed_m_s_, activation_error_m_;
};

}  // namespace craneassist::valves
