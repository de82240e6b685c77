// Sway damping by input shaping (docs/sway.md): a zero-vibration (ZV) shaper on the goal
// velocity the tip scaler moves its reference towards. Each change of the goal is split into two
// steps half a swing period apart, A1 = 1 / (1 + K) now and A2 = K / (1 + K) after
// Td = pi / omega_d (K = exp(-zeta pi / sqrt(1 - zeta^2))): the swing the first half starts, the
// second half cancels. Both steps are the scaler's own jerk-limited transients, so the shaped
// reference keeps every bound the scaler enforces; the shaped goal is a convex combination of
// two goals (no faster than either, a blend of their directions while a turn is being shaped).
// Preallocated at construction; shape() allocates nothing.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace craneassist::scaling {

class SwayShaper {
 public:
  // Goals every period_s, delays up to max_delay_s (a longer half period is cut to it).
  SwayShaper(double period_s, double max_delay_s);

  // Every goal so far at rest (zero).
  void reset() noexcept;

  // Records this cycle's goal and returns it shaped for a pendulum of natural frequency
  // omega_rad_s and damping ratio zeta (omega_rad_s <= 0 or not finite: the goal itself).
  Eigen::Vector3d shape(const Eigen::Vector3d& goal, double omega_rad_s, double zeta) noexcept;

  // The shaper's delay, Td = pi / omega_d (0 with no pendulum).
  static double delay_s(double omega_rad_s, double zeta) noexcept;
  // The weight K of the delayed goal (1 undamped; the shaped goal is (goal + K past) / (1 + K)).
  static double past_weight(double zeta) noexcept;
  // The past goal the next shape() call blends with (the one recorded a delay before it).
  const Eigen::Vector3d& upcoming_past(double omega_rad_s, double zeta) const noexcept;
  // The number of shape() calls whose past goals are already recorded (the delay in periods).
  std::size_t window(double omega_rad_s, double zeta) const noexcept {
    return steps(omega_rad_s, zeta);
  }
  // Replaces the past goal that the k-th next shape() call blends with (k = 0: the next call;
  // k < window()): a shaper started on a motion that was not at rest gets a past of its own.
  void set_upcoming_past(std::size_t k, const Eigen::Vector3d& goal, double omega_rad_s,
                         double zeta) noexcept;

 private:
  std::size_t steps(double omega_rad_s, double zeta) const noexcept;
  double period_s_;
  std::vector<Eigen::Vector3d> history_;  // ring of the last goals, newest at head_
  std::size_t head_ = 0;
};

}  // namespace craneassist::scaling
