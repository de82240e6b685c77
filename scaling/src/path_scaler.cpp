#include "craneassist/scaling/path_scaler.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/dynamics/rigid_body_terms.hpp"

namespace craneassist::scaling {

bool path_terms_and_bounds(const dynamics::CraneModel& model, dynamics::RigidBodyTerms& terms,
                           const JointVector& q, const PathGeometry& geometry, double sdot,
                           const AccelerationLimits& limits, dynamics::PathTerms& path_terms,
                           AccelerationBounds& bounds) noexcept {
  if (terms.path_terms(q, geometry.f1, geometry.f2, sdot, path_terms)) {
    path_acceleration_bounds(model, geometry, path_terms, sdot, limits, bounds);
    return true;
  }
  path_terms.m.setZero(model.dof());
  path_terms.b.setZero(model.dof());
  AccelerationLimits without_dynamics = limits;
  without_dynamics.power_bound = PowerBound::kNone;  // the only bound that reads m and b
  path_acceleration_bounds(model, geometry, path_terms, sdot, without_dynamics, bounds);
  return false;
}

double tracking_factor(double error_m, double error_ok_m) {
  if (!(error_m > error_ok_m)) return 1.0;
  return error_ok_m / error_m;
}

double stop_bound(const AccelerationBounds& bounds, double deceleration_max) {
  return bounds.sddot_min < 0.0 ? bounds.sddot_min : -deceleration_max;
}

SpeedCap lowest_speed_cap(double sdot_request, double tracking_factor, double sdot_joint_limit,
                          const SpeedLimits& speed, const AccelerationBounds& bounds,
                          bool near_singular) {
  const ActiveLimit cylinder_speed =
      near_singular ? ActiveLimit::kSingularity : ActiveLimit::kCylinderSpeed;
  const ActiveLimit cylinder_acceleration =
      near_singular ? ActiveLimit::kSingularity : ActiveLimit::kCylinderAcceleration;
  const SpeedCap candidates[] = {
      {sdot_request * tracking_factor,
       tracking_factor < 1.0 ? ActiveLimit::kTrackingError : ActiveLimit::kNone},
      {speed.sdot_flow, ActiveLimit::kFlow},
      {speed.sdot_cylinder, cylinder_speed},
      {sdot_joint_limit, ActiveLimit::kJointLimit},
      {bounds.sdot_power, bounds.sdot_power_kind},
      {bounds.sdot_acceleration, cylinder_acceleration},
  };
  SpeedCap lowest = candidates[0];
  for (const auto& c : candidates) {
    if (c.value < lowest.value) lowest = c;
  }
  return lowest;
}

PathScaler::PathScaler(const dynamics::CraneModel& model, const PathScalerConfig& config,
                       dynamics::RigidBodyTerms& terms)
    : model_(model),
      config_(config),
      terms_(terms),
      filter_(ScalingFilterConfig{config.period_s, config.jerk_max}) {
  acceleration_limits_.path_acceleration_max = config.acceleration_max;
  acceleration_limits_.power_bound = config.power_bound;
  acceleration_limits_.power_reserve = config.power_reserve;
  acceleration_limits_.path_deceleration_max = config.deceleration_max;
}

void PathScaler::reset(const ScalingFilterState& state) {
  filter_.reset(state);
}

void PathScaler::update(const JointVector& q, const PathGeometry& geometry,
                        const PathScalerInput& in, PathScalerOutput& out) noexcept {
  const double sdot = filter_.state().sdot;

  // Velocity-level limits, uniform along the path. Without the dynamics (a failed step) the
  // acceleration bounds are those that need none: no power bound.
  path_speed_limits(model_, geometry, config_.flow_reserve, out.speed);
  out.dynamics_failed = !path_terms_and_bounds(model_, terms_, q, geometry, sdot,
                                               acceleration_limits_, out.terms, out.bounds);

  const SpeedCap lowest = lowest_speed_cap(in.sdot_request, in.tracking_factor, in.sdot_joint_limit,
                                           out.speed, out.bounds);
  out.sdot_d = std::max(lowest.value, 0.0);
  if (in.stale_input || out.dynamics_failed) out.sdot_d = 0.0;

  // No constraint may force the path to speed up or keep it from stopping (stop_bound).
  const ScalingFilterInput filter_in{
      out.sdot_d, stop_bound(out.bounds, acceleration_limits_.path_deceleration_max),
      out.bounds.sddot_max};
  out.filter_status = filter_.update(filter_in, out.state);

  // What holds the motion back: the failed dynamics, the stale input, a power bound the filter
  // is pressed against, or the lowest velocity-level limit when it is below what the operator
  // asks for.
  out.limit = ActiveLimit::kNone;
  if (out.dynamics_failed) {
    out.limit = ActiveLimit::kDynamicsFailed;
  } else if (in.stale_input) {
    out.limit = ActiveLimit::kStaleInput;
  } else if (out.filter_status == ScalingFilterStatus::kAccelerationLimited &&
             (out.bounds.limit_max == ActiveLimit::kPower ||
              out.bounds.limit_max == ActiveLimit::kPressure) &&
             out.state.sddot >= out.bounds.sddot_max - 1e-9) {
    out.limit = out.bounds.limit_max;
  } else if (lowest.kind != ActiveLimit::kNone && lowest.value < in.sdot_request) {
    out.limit = lowest.kind;
  }
}

}  // namespace craneassist::scaling
