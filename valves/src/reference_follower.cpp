#include "craneassist/valves/reference_follower.hpp"

#include <cmath>

#include "craneassist/dynamics/cylinders.hpp"

namespace craneassist::valves {

ReferenceFollower::ReferenceFollower(const dynamics::CraneModel& model, double position_gain_1_s,
                                     double period_s)
    : model_(model), valves_(model, position_gain_1_s) {
  const int n = model.dof();
  in_.velocity_ref_m_s.setZero(n);
  in_.position_error_m.setZero(n);
  dc_dq_.setZero(n);
  c_ref_.setZero(n);
  c_meas_.setZero(n);
  const double lag_s = model.valves.delay_s + model.valves.time_constant_s;
  q_ref_history_.assign(static_cast<std::size_t>(std::lround(lag_s / period_s)) + 1,
                        JointVector::Zero(n));
}

void ReferenceFollower::reset(const JointVector& q) {
  for (auto& h : q_ref_history_) h = q;
  head_ = 0;
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
}

}  // namespace craneassist::valves
