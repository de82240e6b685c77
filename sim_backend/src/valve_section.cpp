#include "craneassist/sim_backend/valve_section.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/valves/proportional_valves.hpp"

namespace craneassist::sim_backend {

ValveSection::ValveSection(const dynamics::ValveSections& params,
                           const dynamics::ValveDeviation& deviation, double v_max_m_s,
                           double step_s)
    : params_(dynamics::machine_valve(params, deviation)),
      v_max_m_s_(v_max_m_s),
      gain_(deviation.gain),
      shape_(deviation.shape),
      half_play_(0.5 * deviation.hysteresis),
      alpha_(params_.time_constant_s > 0.0 ? 1.0 - std::exp(-step_s / params_.time_constant_s)
                                           : 1.0),
      delay_line_(static_cast<std::size_t>(std::lround(params_.delay_s / step_s)) + 1, 0.0) {}

double ValveSection::velocity_at(double spool) const {
  // The straight line's opening (the model's characteristic), shaped and scaled by the gain.
  const double open =
      std::abs(valves::ProportionalValves::velocity_from_spool(spool, params_.dead_zone, 1.0));
  const double shaped = shape_ == 1.0 ? open : std::pow(open, shape_);
  return std::copysign(gain_ * shaped * v_max_m_s_, spool);
}

double ValveSection::step(double spool_command) {
  const double u = std::isfinite(spool_command) ? std::clamp(spool_command, -1.0, 1.0) : 0.0;
  delay_line_[head_] = u;
  head_ = (head_ + 1) % delay_line_.size();
  const double delayed = delay_line_[head_];  // the oldest sample: delay_s ago
  spool_ += alpha_ * (delayed - spool_);
  // The play: the effective spool follows only once the lagged one is half the play away.
  effective_ = std::clamp(effective_, spool_ - half_play_, spool_ + half_play_);
  return velocity_at(effective_);
}

}  // namespace craneassist::sim_backend
