#include "craneassist/sim_backend/valve_section.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/valves/proportional_valves.hpp"

namespace craneassist::sim_backend {

ValveSection::ValveSection(const dynamics::ValveSections& params, double v_max_m_s, double step_s)
    : params_(params),
      v_max_m_s_(v_max_m_s),
      alpha_(params.time_constant_s > 0.0 ? 1.0 - std::exp(-step_s / params.time_constant_s) : 1.0),
      delay_line_(static_cast<std::size_t>(std::lround(params.delay_s / step_s)) + 1, 0.0) {}

double ValveSection::step(double spool_command) {
  const double u = std::isfinite(spool_command) ? std::clamp(spool_command, -1.0, 1.0) : 0.0;
  delay_line_[head_] = u;
  head_ = (head_ + 1) % delay_line_.size();
  const double delayed = delay_line_[head_];  // the oldest sample: delay_s ago
  spool_ += alpha_ * (delayed - spool_);
  return valves::ProportionalValves::velocity_from_spool(spool_, params_.dead_zone, v_max_m_s_);
}

}  // namespace craneassist::sim_backend
