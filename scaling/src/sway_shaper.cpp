#include "craneassist/scaling/sway_shaper.hpp"

#include <algorithm>
#include <cmath>

namespace craneassist::scaling {

SwayShaper::SwayShaper(double period_s, double max_delay_s)
    : period_s_(period_s),
      history_(static_cast<std::size_t>(std::ceil(std::max(max_delay_s, 0.0) / period_s)) + 1,
               Eigen::Vector3d::Zero()) {}

void SwayShaper::reset() noexcept {
  std::fill(history_.begin(), history_.end(), Eigen::Vector3d::Zero());
  head_ = 0;
}

double SwayShaper::delay_s(double omega_rad_s, double zeta) noexcept {
  if (!(omega_rad_s > 0.0) || !std::isfinite(omega_rad_s)) return 0.0;
  const double z = std::clamp(zeta, 0.0, 0.9);
  return M_PI / (omega_rad_s * std::sqrt(1.0 - z * z));
}

double SwayShaper::past_weight(double zeta) noexcept {
  const double z = std::clamp(zeta, 0.0, 0.9);
  return std::exp(-z * M_PI / std::sqrt(1.0 - z * z));
}

std::size_t SwayShaper::steps(double omega_rad_s, double zeta) const noexcept {
  return std::min(static_cast<std::size_t>(std::lround(delay_s(omega_rad_s, zeta) / period_s_)),
                  history_.size() - 1);
}

const Eigen::Vector3d& SwayShaper::upcoming_past(double omega_rad_s, double zeta) const noexcept {
  const std::size_t next = (head_ + 1) % history_.size();
  return history_[(next + history_.size() - steps(omega_rad_s, zeta)) % history_.size()];
}

void SwayShaper::set_upcoming_past(std::size_t k, const Eigen::Vector3d& goal, double omega_rad_s,
                                   double zeta) noexcept {
  const std::size_t n = history_.size();
  const std::size_t next = (head_ + 1) % n;
  if (k < steps(omega_rad_s, zeta)) history_[(next + n - steps(omega_rad_s, zeta) + k) % n] = goal;
}

Eigen::Vector3d SwayShaper::shape(const Eigen::Vector3d& goal, double omega_rad_s,
                                  double zeta) noexcept {
  head_ = (head_ + 1) % history_.size();
  history_[head_] = goal;
  if (delay_s(omega_rad_s, zeta) <= 0.0) return goal;
  const double k = past_weight(zeta);
  const Eigen::Vector3d& past =
      history_[(head_ + history_.size() - steps(omega_rad_s, zeta)) % history_.size()];
  return (goal + k * past) / (1.0 + k);
}

}  // namespace craneassist::scaling
