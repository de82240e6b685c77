#include "craneassist/scaling/swing_frequency.hpp"

#include <algorithm>

namespace craneassist::scaling {

SwingFrequencyEstimator::SwingFrequencyEstimator(const SwingFrequencySettings& settings)
    : settings_(settings) {
  settings_.periods = std::clamp(settings_.periods, 1, static_cast<int>(ratios_.size()));
}

void SwingFrequencyEstimator::reset() noexcept {
  axes_ = {};
  count_ = 0;
  last_period_s_ = std::numeric_limits<double>::quiet_NaN();
}

void SwingFrequencyEstimator::update(double t_s, double radial_rad, double tangential_rad,
                                     double acceleration_m_s2, double model_period_s) noexcept {
  const bool driven = !(std::abs(acceleration_m_s2) < settings_.free_acceleration_m_s2);
  watch(axes_[0], t_s, radial_rad, driven, model_period_s);
  watch(axes_[1], t_s, tangential_rad, driven, model_period_s);
}

void SwingFrequencyEstimator::watch(Axis& a, double t, double x, bool driven,
                                    double model_period_s) noexcept {
  if (!std::isfinite(x) || !std::isfinite(t) || !(t > a.last_t || std::isnan(a.last_t))) {
    a = Axis{};  // nothing measured (or time going back): start over
    return;
  }
  if (std::isnan(a.last_t)) {
    a.last_t = t;
    a.last_x = x;
    return;
  }
  if (driven) a.free = false;
  a.high = std::max(a.high, x);
  a.low = std::min(a.low, x);
  if (x < -settings_.hysteresis_rad) a.armed = true;
  if (a.armed && a.last_x < 0.0 && x >= 0.0) {
    // An upward crossing, at the time the line between the two samples crosses zero.
    const double crossing = a.last_t + (t - a.last_t) * (-a.last_x) / (x - a.last_x);
    const double period = crossing - a.up_t;  // NaN after a start over
    const bool swung =
        a.high >= settings_.min_amplitude_rad && -a.low >= settings_.min_amplitude_rad;
    if (a.free && swung && std::isfinite(period) && std::isfinite(model_period_s) &&
        period >= settings_.min_ratio * model_period_s &&
        period <= settings_.max_ratio * model_period_s) {
      ratios_[static_cast<std::size_t>(count_) % ratios_.size()] = model_period_s / period;
      ++count_;
      last_period_s_ = period;
    }
    a.up_t = crossing;
    a.high = x;
    a.low = 0.0;
    a.armed = false;
    a.free = !driven;
  }
  a.last_t = t;
  a.last_x = x;
}

double SwingFrequencyEstimator::ratio() const noexcept {
  if (count_ == 0) return 1.0;
  const int n = std::min(count_, settings_.periods);
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const int index = (count_ - 1 - k) % static_cast<int>(ratios_.size());
    sum += ratios_[static_cast<std::size_t>(index)];
  }
  return sum / n;
}

}  // namespace craneassist::scaling
