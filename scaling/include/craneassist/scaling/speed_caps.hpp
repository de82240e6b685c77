// The speed caps and stop bound shared by the scalers of a path (scaling::TipScaler, the
// studies' paths::PathScaler): the per-cycle dynamics with their acceleration bounds, the
// tracking-error slow-down and the lowest of the velocity-level limits.
#pragma once

#include "craneassist/dynamics/path_terms.hpp"
#include "craneassist/scaling/active_limit.hpp"
#include "craneassist/scaling/path_constraints.hpp"

namespace craneassist::dynamics {
class RigidBodyTerms;
}

namespace craneassist::scaling {

// The scalers' per-cycle dynamics: m, b at (q, sdot) from `terms` and the acceleration bounds
// with them. When the dynamics step fails: zero m and b, the bounds that need no dynamics
// (limits without the power bound), and false. Allocates nothing, throws nothing.
[[nodiscard]] bool path_terms_and_bounds(const dynamics::CraneModel& model,
                                         dynamics::RigidBodyTerms& terms, const JointVector& q,
                                         const PathGeometry& geometry, double sdot,
                                         const AccelerationLimits& limits,
                                         dynamics::PathTerms& path_terms,
                                         AccelerationBounds& bounds) noexcept;

// delta(|e|) of docs/algorithms.md section 6: 1 below e_ok, e_ok / |e| above.
double tracking_factor(double error_m, double error_ok_m);

// The lower bound on sddot the scalers use: the constraints' own where it allows slowing down;
// where it does not (a lower bound at or above zero: the cylinder accelerations on a sharply
// curved joint path at speed), the path's deceleration bound: no constraint may force the path
// to speed up or keep it from stopping.
double stop_bound(const AccelerationBounds& bounds, double deceleration_max);

// The lowest of the velocity-level limits on the path speed and what sets it: the operator's
// request times the tracking factor, pump flow, cylinder speeds, end damping, the quasi-static
// power and the path curvature (cylinder accelerations). near_singular reports the cylinder
// limits as kSingularity: the pose, not the cylinder, is what makes them low.
struct SpeedCap {
  double value = 0.0;
  ActiveLimit kind = ActiveLimit::kNone;
};
SpeedCap lowest_speed_cap(double sdot_request, double tracking_factor, double sdot_joint_limit,
                          const SpeedLimits& speed, const AccelerationBounds& bounds,
                          bool near_singular = false);

}  // namespace craneassist::scaling
