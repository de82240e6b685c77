#include "craneassist/valves/reference_follower.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/valve_table.hpp"

namespace craneassist::valves {
namespace {

// The lead's search: steps of the predicted return to the wanted command (2 / max_step at most
// matter), and bisections of the command.
constexpr int kMaxLeadSteps = 64;
constexpr int kLeadBisections = 20;

}  // namespace

double max_spool_step(const dynamics::ValveSections& valves, double period_s) {
  return valves.stroke_time_s > 0.0 ? std::min(period_s / valves.stroke_time_s, 2.0) : 2.0;
}

ReferenceFollower::ReferenceFollower(const dynamics::CraneModel& model, double position_gain_1_s,
                                     double period_s, double activation_speed_m_s,
                                     double activation_error_m)
    : model_(model),
      valves_(model, position_gain_1_s, activation_speed_m_s, activation_error_m),
      period_s_(period_s),
      max_step_(max_spool_step(model.valves, period_s)) {
  const int n = model.dof();
  in_.velocity_ref_m_s.setZero(n);
  in_.position_error_m.setZero(n);
  dc_dq_.setZero(n);
  c_ref_.setZero(n);
  c_meas_.setZero(n);
  spool_estimate_.setZero(n);
  last_command_.setZero(n);
  zero_.setZero(n);
  lag_alpha_.setZero(n);
  std::size_t longest = 0;
  for (int i = 0; i < n; ++i) {
    const double tau = dynamics::section_time_constant_s(model, i);
    lag_alpha_[i] = tau > 0.0 ? 1.0 - std::exp(-period_s / tau) : 1.0;
    const double lag_s = dynamics::section_delay_s(model, i) + tau;
    lag_cycles_[static_cast<std::size_t>(i)] =
        static_cast<std::size_t>(std::lround(lag_s / period_s));
    longest = std::max(longest, lag_cycles_[static_cast<std::size_t>(i)]);
  }
  q_ref_history_.assign(longest + 1, JointVector::Zero(n));
}

void ReferenceFollower::reset(const JointVector& q) {
  for (auto& h : q_ref_history_) h = q;
  head_ = 0;
  spool_estimate_.setZero();
  last_command_.setZero();
}

void ReferenceFollower::set_command_period(double command_period_s) {
  lead_ = !(command_period_s > period_s_ * (1.0 + 1e-6));
}

double ReferenceFollower::send(int i, double command) {
  const double last = last_command_[i];
  command = std::clamp(std::clamp(command, -1.0, 1.0), last - max_step_, last + max_step_);
  spool_estimate_[i] += lag_alpha_[i] * (command - spool_estimate_[i]);
  last_command_[i] = command;
  return command;
}

bool ReferenceFollower::neutral(ValveCommand& out) {
  const int n = model_.dof();
  out.spool.resize(n);
  bool all = true;
  for (int i = 0; i < n; ++i) {
    out.spool[i] = send(i, 0.0);
    all = all && out.spool[i] == 0.0;
  }
  return all;
}

void ReferenceFollower::update(const JointVector& q_ref, const JointVector& qdot_ref,
                               const JointVector* q_meas, ValveCommand& out, bool with_lead) {
  follow(q_ref, qdot_ref, q_meas, -1.0, with_lead, out);
}

void ReferenceFollower::hold(const JointVector& q_ref, const JointVector& q_meas,
                             double hold_error_m, ValveCommand& out) {
  follow(q_ref, zero_, &q_meas, std::max(hold_error_m, 0.0), false, out);
}

void ReferenceFollower::follow(const JointVector& q_ref, const JointVector& qdot_ref,
                               const JointVector* q_meas, double hold_error_m, bool with_lead,
                               ValveCommand& out) {
  const bool holding = hold_error_m >= 0.0;
  const int n = model_.dof();
  dynamics::cylinder_arms(model_, q_ref, dc_dq_);
  for (int i = 0; i < n; ++i) in_.velocity_ref_m_s[i] = dc_dq_[i] * qdot_ref[i];
  q_ref_history_[head_] = q_ref;
  head_ = (head_ + 1) % q_ref_history_.size();  // now the oldest entry
  if (q_meas != nullptr) {
    // Each section against the reference of its own valve lag ago.
    const std::size_t size = q_ref_history_.size();
    for (int i = 0; i < n; ++i) {
      const std::size_t age = lag_cycles_[static_cast<std::size_t>(i)];
      const JointVector& q_old = q_ref_history_[(head_ + (size - 1 - age)) % size];
      c_ref_[i] =
          dynamics::cylinder_length(model_.cylinders[static_cast<std::size_t>(i)], q_old[i]);
    }
    dynamics::cylinder_lengths(model_, *q_meas, c_meas_);
    in_.position_error_m = c_ref_ - c_meas_;
  } else {
    in_.position_error_m.setZero(n);
  }
  valves_.update(in_, out);
  // Compensation of the spool lag while a spool still has to cross the dead band to the side it
  // is wanted on (no flow passes there, so a fast crossing costs nothing): the largest command,
  // at most the wanted one plus the dead band's width (and the way back to neutral while the
  // spool is still on the other side), that the spool estimate does not carry
  // past the wanted position when the command then comes back to it at the slew-rate limit (the
  // deadbeat step when there is no limit). Outside the band the wanted position goes through
  // unchanged, so feedback corrections are not amplified. Only when every command reaches the
  // valves (held for two cycles, the lead would overshoot), and never while holding.
  for (int i = 0; i < n; ++i) {
    double wanted = out.spool[i];
    if (holding && std::abs(in_.position_error_m[i]) < hold_error_m) wanted = 0.0;
    double command = wanted;
    if (wanted != 0.0 && lead_ && with_lead && !holding) {
      const double side = wanted > 0.0 ? 1.0 : -1.0;
      const double band = std::abs(valves_.dead_band_edge(i, wanted));
      const double x = side * spool_estimate_[i];  // how far towards the wanted edge
      if (x < band) {
        command = side * lead(x, side * last_command_[i], std::abs(wanted), band, lag_alpha_[i]);
      }
    }
    out.spool[i] = send(i, command);
  }
}

double ReferenceFollower::lead(double x, double last, double target, double band,
                               double alpha) const {
  // Sided coordinates: x the spool estimate, last the last command, target the wanted command.
  const double low = std::max(target, last - max_step_);
  // At most the wanted command plus the way to its band edge from neutral (the dead band's
  // width), and the way back to neutral when the spool is still on the other side.
  const double over = band - std::min(x, 0.0);
  const double high = std::min({target + over, 1.0, last + max_step_});
  if (!(high > low)) return std::max(low, std::min(target, high));
  // Where the estimate ends when the command c is sent now, then steps back to the target.
  auto peak = [&](double c) {
    double e = x + alpha * (c - x);
    double top = e;
    for (int k = 0; k < kMaxLeadSteps && c > target; ++k) {
      c = std::max(c - max_step_, target);
      e += alpha * (c - e);
      top = std::max(top, e);
    }
    return top;
  };
  if (peak(high) <= target) return high;
  if (peak(low) > target) return low;
  double lo = low, hi = high;  // peak(lo) <= target < peak(hi)
  for (int k = 0; k < kLeadBisections; ++k) {
    const double mid = 0.5 * (lo + hi);
    (peak(mid) <= target ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace craneassist::valves
