// Valve commands that make the machine follow a joint reference: the cylinder velocity
// reference through the dead-zone inverse, plus P feedback on the cylinder position error
// measured against the reference of one valve delay ago (transport delay plus spool lag), so the
// valve's own dead time is not mistaken for a tracking error (a Smith-predictor-style
// compensation). The spool's first-order lag is compensated through the dead zone: the
// follower keeps an estimate of every spool position and, while a spool still has to cross the
// dead zone on the side it is wanted, leads it: the largest command, at most the wanted one plus
// the dead band's width (and the way back to neutral while the spool is still on the other side),
// that does not carry the estimate past the wanted position once the
// command steps back to it at the slew-rate limit (without a limit: deadbeat, the wanted position
// within one period). All sections then cross together when a motion starts or a feedback
// correction changes side, instead of the small commands lagging behind the large ones and
// bending the tip path; beyond the dead zone the wanted position passes unchanged. Every command,
// neutral included, then moves at most period / hydraulics.valves.stroke_time from the last one
// (the slew-rate limit of a valve driver's ramp). The lead is tuned to the section's spool lag:
// its table's time constant and delay where craneassist calibrate measured them, else
// hydraulics.valves'. A machine whose spools are much faster than that makes the lead overshoot
// into flow and the feedback hunt (docs/valves.md#the-machine-it-meets): identify them first.
// While a stop settles (hold()) there is no lead.
// Preallocated history; update() allocates nothing.
#pragma once

#include <array>
#include <vector>

#include "craneassist/dynamics/model.hpp"
#include "craneassist/valves/machine_interface.hpp"
#include "craneassist/valves/proportional_valves.hpp"

namespace craneassist::valves {

// The slew-rate limit hydraulics.valves.stroke_time sets: the most a spool command may move per
// control period (2: no limit, a full reversal in one period).
double max_spool_step(const dynamics::ValveSections& valves, double period_s);

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
  // there is none (feed-forward only); lead false: no dead-band lead this cycle (a stop).
  void update(const JointVector& q_ref, const JointVector& qdot_ref, const JointVector* q_meas,
              ValveCommand& out, bool with_lead = true);

  // Holds the machine at a reference at rest (a stop settling): P feedback only, no dead-band
  // lead, and a section whose cylinder position error is below hold_error_m is closed (its
  // command goes to neutral) instead of hunting across the dead band.
  void hold(const JointVector& q_ref, const JointVector& q_meas, double hold_error_m,
            ValveCommand& out);

  // Moves every command towards neutral at the slew-rate limit (the estimate follows); true once
  // every command is neutral.
  bool neutral(ValveCommand& out);

  // The most a command moves per update (2: no limit, a full reversal in one cycle).
  double max_step() const { return max_step_; }
  // The follower's estimate of section i's spool position (the model's lag on the commands).
  double spool_estimate(int i) const { return spool_estimate_[i]; }

  // Cylinder-position reference of one valve delay ago (for tracking-error measures).
  const JointVector& delayed_reference_q() const { return q_ref_history_[head_]; }

 private:
  // update() and hold(): the wanted commands (DZI plus P), the lead, the slew-rate limit.
  void follow(const JointVector& q_ref, const JointVector& qdot_ref, const JointVector* q_meas,
              double hold_error_m, bool with_lead, ValveCommand& out);
  // The dead-band lead in a section's sided coordinates (docs/valves.md), planned with the
  // lag factor alpha per period.
  double lead(double x, double last, double target, double band, double alpha) const;
  // command moved at most max_step_ from section i's last command; the estimate follows.
  double send(int i, double command);

  const dynamics::CraneModel& model_;
  ProportionalValves valves_;
  ProportionalValvesInput in_;
  JointVector dc_dq_, c_ref_, c_meas_;
  JointVector spool_estimate_;
  JointVector last_command_;  // what was sent last cycle
  JointVector zero_;
  double period_s_;
  bool lead_ = true;  // every command reaches the valves: the dead-zone lead is safe
  // Per section: the share of the remaining spool travel the lag covers in one period, and the
  // valve's delay plus lag in periods (the reference's age for the feedback).
  JointVector lag_alpha_;
  std::array<std::size_t, dynamics::kMaxJoints> lag_cycles_{};
  double max_step_ = 2.0;                   // the slew-rate limit per update (2: none)
  std::vector<JointVector> q_ref_history_;  // the longest lag's
  std::size_t head_ = 0;
};

}  // namespace craneassist::valves
