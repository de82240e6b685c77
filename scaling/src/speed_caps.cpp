#include "craneassist/scaling/speed_caps.hpp"

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

}  // namespace craneassist::scaling
