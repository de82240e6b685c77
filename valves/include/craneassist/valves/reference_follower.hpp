// Valve commands that make the machine follow a joint reference: the cylinder velocity
// reference through the dead-zone inverse, plus P feedback on the cylinder position error
// measured against the reference of one valve delay ago (transport delay plus spool lag), so the
// valve's own dead time is not mistaken for a tracking error (a Smith-predictor-style
// compensation). The spool's first-order lag is compensated through the dead zone: the
// follower keeps an estimate of every spool position and, while a spool still has to cross the
// dead zone, commands what brings it to the wanted position within one period (deadbeat,
// clipped to the spool range). All sections then cross together when a motion starts or
// reverses, instead of the small commands lagging behind the large ones and bending the tip
// path; beyond the dead zone the wanted position passes unchanged. Preallocated history; update()
// allocates nothing.
#pragma once

#include <vector>

#include "craneassist/dynamics/model.hpp"
#include "craneassist/valves/machine_interface.hpp"
#include "craneassist/valves/proportional_valves.hpp"

namespace craneassist::valves {

class ReferenceFollower {
 public:
  ReferenceFollower(const dynamics::CraneModel& model, double position_gain_1_s, double period_s,
                    double activation_speed_m_s = 0.0, double activation_error_m = 0.0);

  // Fills the history with q (the machine at rest at q).
  void reset(const JointVector& q);

  // How often a command reaches the valves (MachineInterface::command_period_s; 0: every
  // update). The spool lag is compensated through the dead zone by a one-cycle lead only when
  // every command reaches the valves: a lead held for longer (a bus that sends every 20 ms)
  // overshoots the dead zone into flow.
  void set_command_period(double command_period_s);

  // q_ref, qdot_ref: this cycle's joint reference; q_meas: the measurement, or nullptr when
  // there is none (feed-forward only).
  void update(const JointVector& q_ref, const JointVector& qdot_ref, const JointVector* q_meas,
              ValveCommand& out);

  // Neutral valves (the estimate follows).
  void neutral(ValveCommand& out);

  // Cylinder-position reference of one valve delay ago (for tracking-error measures).
  const JointVector& delayed_reference_q() const { return q_ref_history_[head_]; }

 private:
  const dynamics::CraneModel& model_;
  ProportionalValves valves_;
  ProportionalValvesInput in_;
  JointVector dc_dq_, c_ref_, c_meas_;
  JointVector spool_estimate_;
  double period_s_;
  bool lead_ = true;  // every command reaches the valves: the dead-zone lead is safe
  double lag_alpha_;  // share of the remaining spool travel the lag covers in one period
  std::vector<JointVector> q_ref_history_;
  std::size_t head_ = 0;
};

}  // namespace craneassist::valves
