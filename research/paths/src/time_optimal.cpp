#include "craneassist/paths/time_optimal.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "craneassist/dynamics/rigid_body_terms.hpp"

namespace craneassist::paths {
using namespace craneassist::scaling;  // the scaling room these paths are built on
namespace {

constexpr double kTopSpeedFallback = 50.0;  // m/s: when nothing caps the speed

}  // namespace

TimeOptimalResult time_optimal_profile(const dynamics::CraneModel& model,
                                       dynamics::RigidBodyTerms& terms,
                                       const std::vector<PathSample>& samples,
                                       const TimeOptimalSettings& settings) {
  TimeOptimalResult out;
  const std::size_t n = samples.size();
  if (n < 2) return out;

  // Velocity-level caps per sample.
  std::vector<double> cap(n);
  out.limit.assign(n, ActiveLimit::kNone);
  SpeedLimits limits;
  for (std::size_t k = 0; k < n; ++k) {
    path_speed_limits(model, samples[k].geometry, settings.flow_reserve, limits);
    cap[k] = std::min(samples[k].sdot_cap, kTopSpeedFallback);
    if (limits.sdot_flow < cap[k]) {
      cap[k] = limits.sdot_flow;
      out.limit[k] = ActiveLimit::kFlow;
    }
    if (limits.sdot_cylinder < cap[k]) {
      cap[k] = limits.sdot_cylinder;
      out.limit[k] = ActiveLimit::kCylinderSpeed;
    }
    out.top_speed = std::max(out.top_speed, cap[k]);
  }

  // Acceleration bounds at a sample and path speed: m(s), b(s) from the ODE model.
  AccelerationLimits accel;
  accel.path_acceleration_max = settings.acceleration_max;
  accel.path_deceleration_max = settings.deceleration_max;
  accel.power_bound = settings.power_bound;
  accel.power_reserve = settings.power_reserve;
  dynamics::PathTerms path_terms;
  AccelerationBounds bounds;
  auto path_terms_and_bounds = [&](std::size_t k, double v) {
    const auto& g = samples[k].geometry;
    // Offline: a failed dynamics step (ODE out of memory) is an error here, not a stop.
    if (!terms.path_terms(samples[k].q, g.f1, g.f2, v, path_terms)) {
      throw std::runtime_error(
          "time_optimal_profile: the ODE dynamics step failed (out of memory)");
    }
    path_acceleration_bounds(model, g, path_terms, v, accel, bounds);
  };
  auto bounds_at = [&](std::size_t k, double v, double& lo, double& hi) {
    path_terms_and_bounds(k, v);
    lo = std::min(bounds.sddot_min, 0.0);
    hi = bounds.sddot_max < bounds.sddot_min ? lo : bounds.sddot_max;
  };

  // Forward at the largest acceleration (the squared speed b moves by 2 a ds), clipped to the
  // caps; backward from rest at the end at the largest deceleration, clipped to the forward
  // profile. Their minimum is the fastest admissible profile (Bobrow, Dubowsky and Gibson's
  // integration; the caps' dips are reached by the backward pass).
  std::vector<double> b(n, 0.0);
  double lo = 0.0, hi = 0.0;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const double ds = samples[k + 1].s - samples[k].s;
    bounds_at(k, std::sqrt(b[k]), lo, hi);
    b[k + 1] = std::clamp(b[k] + 2.0 * hi * ds, 0.0, cap[k + 1] * cap[k + 1]);
  }
  b[n - 1] = 0.0;
  for (std::size_t k = n - 1; k-- > 0;) {
    const double ds = samples[k + 1].s - samples[k].s;
    bounds_at(k + 1, std::sqrt(b[k + 1]), lo, hi);
    b[k] = std::min(b[k], b[k + 1] - 2.0 * lo * ds);
  }
  b[0] = 0.0;

  // The time, and where the path cannot go on (two samples in a row at rest).
  out.sdot.assign(n, 0.0);
  double time = 0.0;
  for (std::size_t k = 0; k < n; ++k) out.sdot[k] = std::sqrt(std::max(b[k], 0.0));
  out.segments.resize(n - 1);
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const double v = out.sdot[k] + out.sdot[k + 1];
    if (!(v > 0.0)) {
      out.blocked_sample = static_cast<int>(k);
      bounds_at(k, 0.0, lo, hi);
      out.blocked_acceleration_max = hi;
      out.segments.clear();
      return out;
    }
    auto& seg = out.segments[k];
    seg.time_s = 2.0 * (samples[k + 1].s - samples[k].s) / v;
    time += seg.time_s;
    // At a cap at both ends (within 0.5 %): the cap; otherwise speeding up or slowing down, and
    // the bound that sets that side at the state the step is taken from.
    const bool capped = out.sdot[k] >= 0.995 * cap[k] && out.sdot[k + 1] >= 0.995 * cap[k + 1];
    if (capped) {
      seg.phase = BoundPhase::kSpeedCap;
      seg.limit = out.limit[k + 1];
    } else if (b[k + 1] >= b[k]) {
      seg.phase = BoundPhase::kAccelerating;
      path_terms_and_bounds(k, out.sdot[k]);
      seg.limit = bounds.limit_max;
    } else {
      seg.phase = BoundPhase::kDecelerating;
      path_terms_and_bounds(k + 1, out.sdot[k + 1]);
      seg.limit = bounds.limit_min;
    }
  }
  out.ok = true;
  out.time_s = time;
  return out;
}

}  // namespace craneassist::paths
