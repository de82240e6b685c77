#include "craneassist/valves/reference_follower.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/dynamics/cylinders.hpp"

namespace craneassist::valves {

ReferenceFollower::ReferenceFollower(const dynamics::CraneModel& model, double position_gain_1_s,
                                     double period_s, double activation_speed_m_s,
                                     double activation_error_m)
    : model_(model),
      valves_(model, position_gain_1_s, activation_speed_m_s, activation_error_m),
      period_s_(period_s),
      lag_alpha_(model.valves.time_constant_s > 0.0
                     ? 1.0 - std::exp(-period_s / model.valves.time_constant_s)
                     : 1.0) {
  const int n = model.dof();
  in_.velocity_ref_m_s.setZero(n);
  in_.position_error_m.setZero(n);
  dc_dq_.setZero(n);
  c_ref_.setZero(n);
  c_meas_.setZero(n);
  spool_estimate_.setZero(n);
  const double lag_s = model.valves.delay_s + model.valves.time_constant_s;
  q_ref_history_.assign(static_cast<std::size_t>(std::lround(lag_s / period_s)) + 1,
                        JointVector::Zero(n));
}

void ReferenceFollower::reset(const JointVector& q) {
  for (auto& h : q_ref_history_) h = q;
  head_ = 0;
  spool_estimate_.setZero();
}

void ReferenceFollower::set_command_period(double command_period_s) {
  lead_ = !(command_period_s > period_s_ * (1.0 + 1e-6));
}

void ReferenceFollower::neutral(ValveCommand& out) {
  out.spool.setZero(model_.dof());
  spool_estimate_ += lag_alpha_ * (out.spool - spool_estimate_);
}

void ReferenceFollower::update(const JointVector& q_ref, const JointVector& qdot_ref,
                               const JointVector* q_meas, ValveCommand& out) {
  const int n = model_.dof();
  dynamics::cylinder_arms(model_, q_ref, dc_dq_);
  for (int i = 0; i < n; ++i) in_.velocity_ref_m_s[i] = dc_dq_[i] * qdot_ref[i];
  q_ref_history_[head_] = q_ref;
  head_ = (head_ + 1) % q_ref_history_.size();  // now the oldest entry
  if (q_meas != nullptr) {
    dynamics::cylinder_lengths(model_, q_ref_history_[head_], c_ref_);
    dynamics::cylinder_lengths(model_, *q_meas, c_meas_);
    in_.position_error_m = c_ref_ - c_meas_;
  } else {
    in_.position_error_m.setZero(n);
  }
  valves_.update(in_, out);
  // Deadbeat compensation of the spool lag while a spool still has to cross the dead zone to the
  // side it is wanted on (no flow passes there, so a fast crossing costs nothing); outside it
  // the wanted position goes through unchanged, so feedback corrections are not amplified. Only
  // when every command reaches the valves: held for two cycles, the lead would overshoot.
  for (int i = 0; i < n; ++i) {
    const double wanted = out.spool[i];
    const double estimate = spool_estimate_[i];
    // The dead band on the wanted side (the section's table, or the straight line's dead_zone).
    const double edge = wanted != 0.0 ? valves_.dead_band_edge(i, wanted) : 0.0;
    const bool crossing =
        wanted != 0.0 && (estimate * wanted <= 0.0 || std::abs(estimate) < std::abs(edge));
    const double command = crossing && lead_
                               ? std::clamp(estimate + (wanted - estimate) / lag_alpha_, -1.0, 1.0)
                               : wanted;
    spool_estimate_[i] += lag_alpha_ * (command - spool_estimate_[i]);
    out.spool[i] = command;
  }
}

}  // namespace craneassist::valves
