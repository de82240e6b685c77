#include "craneassist/paths/path_scaler.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/dynamics/rigid_body_terms.hpp"

namespace craneassist::paths {
using namespace craneassist::scaling;  // the scaling room these paths are built on

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

}  // namespace craneassist::paths
