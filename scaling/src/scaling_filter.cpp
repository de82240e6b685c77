#include "craneassist/scaling/scaling_filter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace craneassist::scaling {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kEps = std::numeric_limits<double>::epsilon();

bool positive_finite(double x) {
  return std::isfinite(x) && x > 0.0;
}

// The end-of-step acceleration x with T x/2 + B(x) = r (B = braking_velocity_change). The left
// side is odd and piecewise linear in x with kinks at multiples of J T: on
// ((n-1) J T, n J T] it is T (n x - J T n (n-1)/2), and it takes the value J T^2 n (n+1)/2 at
// x = n J T. So n is the segment with J T^2 (n-1) n/2 < |r| <= J T^2 n (n+1)/2.
double tracking_acceleration(double r, double jerk, double period) {
  if (r == 0.0) return 0.0;
  const double q = std::abs(r) / (jerk * period * period);
  if (!(q < 1e30)) return std::copysign(kInf, r);
  double n = std::ceil(0.5 * (std::sqrt(1.0 + 8.0 * q) - 1.0));
  n = std::max(n, 1.0);
  if (0.5 * n * (n + 1.0) < q) {
    n += 1.0;
  } else if (n > 1.0 && 0.5 * (n - 1.0) * n >= q) {
    n -= 1.0;
  }
  const double x = std::abs(r) / (n * period) + 0.5 * jerk * period * (n - 1.0);
  return std::copysign(x, r);
}

}  // namespace

const char* to_string(ScalingFilterStatus status) {
  switch (status) {
    case ScalingFilterStatus::kTracking:
      return "tracking";
    case ScalingFilterStatus::kAccelerationLimited:
      return "acceleration_limited";
    case ScalingFilterStatus::kReenteringBounds:
      return "reentering_bounds";
    case ScalingFilterStatus::kStopped:
      return "stopped";
  }
  return "?";
}

double braking_velocity_change(double sddot, double jerk_max, double period_s) {
  if (!(jerk_max > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double m = std::abs(sddot);
  if (!(period_s > 0.0) || std::isinf(m)) return std::copysign(m * m / (2.0 * jerk_max), sddot);
  const double step = jerk_max * period_s;
  const double n = std::ceil(m / step);
  if (n <= 1.0) return 0.5 * sddot * period_s;
  return std::copysign(period_s * (0.5 * m + (n - 1.0) * m - 0.5 * step * n * (n - 1.0)), sddot);
}

double max_speed_to_stop_within(double distance, double decel_max, double jerk_max) {
  if (!(distance > 0.0) || !(decel_max > 0.0) || !(jerk_max > 0.0)) return 0.0;
  if (std::isinf(distance)) return kInf;
  // Triangular profile (the stop never reaches decel_max): d = v sqrt(v/J).
  const double v_tri = std::cbrt(jerk_max * distance * distance);
  if (std::isinf(decel_max) || v_tri * jerk_max <= decel_max * decel_max) return v_tri;
  // Trapezoidal profile: v^2 + v A^2/J - 2 A d = 0, the positive root in its cancellation-free
  // form 2c / (b + sqrt(b^2 + 4c)), with b = A^2/J (0 for J = inf) and c = 2 A d.
  const double b = decel_max * decel_max / jerk_max;
  const double c = 2.0 * decel_max * distance;
  return 2.0 * c / (b + std::sqrt(b * b + 4.0 * c));
}

double stop_distance(double speed, double decel_max, double jerk_max) {
  if (!(speed > 0.0)) return 0.0;
  if (!(decel_max > 0.0) || !(jerk_max > 0.0)) return kInf;
  if (std::isinf(jerk_max)) return speed * speed / (2.0 * decel_max);
  if (std::isinf(decel_max) || speed * jerk_max <= decel_max * decel_max) {
    return std::sqrt(speed * speed * speed / jerk_max);
  }
  return speed * speed / (2.0 * decel_max) + speed * decel_max / (2.0 * jerk_max);
}

double braking_distance(double speed, double acceleration, double decel_max, double jerk_max) {
  if (!(acceleration > 0.0) || std::isinf(jerk_max)) {
    return stop_distance(speed, decel_max, jerk_max);
  }
  const double t = acceleration / jerk_max;  // until the acceleration is zero
  const double ramp = speed * t + 0.5 * acceleration * t * t - jerk_max * t * t * t / 6.0;
  return ramp + stop_distance(speed + 0.5 * acceleration * t, decel_max, jerk_max);
}

ScalingFilter::ScalingFilter(const ScalingFilterConfig& config)
    : config_(config),
      valid_(positive_finite(config.period_s) && positive_finite(config.jerk_max)) {}

void ScalingFilter::reset(const ScalingFilterState& state) {
  auto finite_or_zero = [](double x) { return std::isfinite(x) ? x : 0.0; };
  state_.s = finite_or_zero(state.s);
  state_.sdot = finite_or_zero(state.sdot);
  state_.sddot = finite_or_zero(state.sddot);
  state_.sdddot = finite_or_zero(state.sdddot);
}

ScalingFilterStatus ScalingFilter::update(const ScalingFilterInput& in,
                                          ScalingFilterState& out) noexcept {
  const double period = config_.period_s;
  const double jerk = config_.jerk_max;
  const double a = state_.sddot;
  const double v = state_.sdot;

  if (!valid_) {
    state_.sdddot = 0.0;
    out = state_;
    return ScalingFilterStatus::kStopped;
  }

  const double target = std::isfinite(in.sdot_d) ? in.sdot_d : 0.0;
  double lo = std::isnan(in.sddot_min) ? -kInf : in.sddot_min;
  double hi = std::isnan(in.sddot_max) ? kInf : in.sddot_max;
  if (lo > hi) lo = hi;  // empty: decelerate, both bounds = the lower value

  const bool zero_command = target == 0.0;
  if (zero_command && v == 0.0 && a == 0.0) {  // at rest: hold, whatever the bounds say
    state_.sdddot = 0.0;
    out = state_;
    return ScalingFilterStatus::kStopped;
  }

  // Tracking choice: the end-of-step acceleration whose braking prediction lands on target.
  // A residual at the rounding level counts as "on target", so the final braking step lands
  // exactly and the steady state does not chatter.
  double r = target - v - 0.5 * period * a;
  const double tol = 1e-9 * jerk * period * period +
                     64.0 * kEps * (std::abs(v) + std::abs(target) + period * std::abs(a));
  if (std::abs(r) <= tol) r = 0.0;
  // x_land: the end-of-step acceleration that puts this step's sdot exactly on target
  // (v + T (a + x)/2 = target). When the target is ahead (target - v) but the braking
  // prediction says "slow down" (r of the other sign), the step must not carry sdot past the
  // target either: then x_land is the tighter limit.
  const double x_land = 2.0 * r / period;
  const double ahead = target - v;
  double x_track = tracking_acceleration(r, jerk, period);
  if ((ahead > 0.0 && r < 0.0) || (ahead < 0.0 && r > 0.0)) x_track = x_land;

  if (zero_command) {
    // Relax only the bound that contradicts coming to rest (see the header).
    const bool forward = v != 0.0 ? v > 0.0 : a > 0.0;
    if (forward) {
      if (lo >= 0.0) lo = -kInf;
      if (hi < 0.0) hi = std::max(hi, std::min(x_track, 0.0));
    } else {
      if (hi <= 0.0) hi = kInf;
      if (lo > 0.0) lo = std::min(lo, std::max(x_track, 0.0));
    }
  }

  const double window_lo = a - jerk * period;
  const double window_hi = a + jerk * period;
  const double lower = std::max(window_lo, lo);
  const double upper = std::min(window_hi, hi);

  double x;
  ScalingFilterStatus status = ScalingFilterStatus::kTracking;
  if (lower <= upper) {
    x = std::min(std::max(x_track, lower), upper);
    if ((x_track > upper && hi <= window_hi) || (x_track < lower && lo >= window_lo)) {
      status = ScalingFilterStatus::kAccelerationLimited;
    }
  } else {  // the bounds are out of reach this step: full jerk towards them
    x = window_lo > hi ? window_lo : window_hi;
    status = ScalingFilterStatus::kReenteringBounds;
  }

  const double j = std::min(std::max((x - a) / period, -jerk), jerk);
  double v_next = v + 0.5 * period * (a + x);  // = v + a T + j T^2/2
  if (x == x_land) v_next = target;            // what the rounding would miss by an ulp
  state_.s += period * v + period * period * (2.0 * a + x) / 6.0;  // = v T + a T^2/2 + j T^3/6
  state_.sdot = v_next;
  state_.sddot = x;
  state_.sdddot = j;
  out = state_;

  if (zero_command && v_next == 0.0 && x == 0.0) return ScalingFilterStatus::kStopped;
  return status;
}

}  // namespace craneassist::scaling
