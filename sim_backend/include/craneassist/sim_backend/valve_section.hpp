// One pressure-compensated valve section as the machine has it: transport delay, first-order
// spool lag, hysteresis (play), dead zone, and beyond it the cylinder velocity
// gain * v_max * opening^shape (dynamics::ValveDeviation; the model's straight line by default).
// The delay line is preallocated; stepping allocates nothing.
#pragma once

#include <vector>

#include "craneassist/dynamics/machine_deviation.hpp"
#include "craneassist/dynamics/model.hpp"

namespace craneassist::sim_backend {

class ValveSection {
 public:
  // params: the model's sections; deviation: where this machine's section differs.
  ValveSection(const dynamics::ValveSections& params, const dynamics::ValveDeviation& deviation,
               double v_max_m_s, double step_s);
  ValveSection(const dynamics::ValveSections& params, double v_max_m_s, double step_s)
      : ValveSection(params, dynamics::ValveDeviation{}, v_max_m_s, step_s) {}

  // Advances one simulation step with spool command u in [-1, 1]; returns the cylinder velocity
  // the section asks for (before pump saturation), m/s.
  double step(double spool_command);

  // The effective spool position (after the lag and the hysteresis).
  double spool_position() const { return effective_; }

  // The steady cylinder velocity of this section at an effective spool position.
  double velocity_at(double spool) const;

 private:
  dynamics::ValveSections params_;  // the machine's
  double v_max_m_s_;
  double gain_, shape_, half_play_;
  double alpha_;  // lag update factor per step
  std::vector<double> delay_line_;
  std::size_t head_ = 0;
  double spool_ = 0.0;      // the lagged spool
  double effective_ = 0.0;  // after the play
};

}  // namespace craneassist::sim_backend
