// One pressure-compensated valve section: transport delay, first-order spool lag, dead zone.
// The delay line is preallocated; stepping allocates nothing.
#pragma once

#include <vector>

#include "craneassist/dynamics/model.hpp"

namespace craneassist::sim_backend {

class ValveSection {
 public:
  ValveSection(const dynamics::ValveSections& params, double v_max_m_s, double step_s);

  // Advances one simulation step with spool command u in [-1, 1]; returns the cylinder velocity
  // the section asks for (before pump saturation), m/s.
  double step(double spool_command);

  double spool_position() const { return spool_; }

 private:
  dynamics::ValveSections params_;
  double v_max_m_s_;
  double alpha_;  // lag update factor per step
  std::vector<double> delay_line_;
  std::size_t head_ = 0;
  double spool_ = 0.0;
};

}  // namespace craneassist::sim_backend
