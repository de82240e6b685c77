// The per-cycle scaling step of a path q = f(s): velocity-level limits, the load-sensing power
// and acceleration bounds from the ODE dynamics, and the jerk-bounded scaling filter
// ("Real-time trajectory scaling algorithm for hydraulic manipulators subject to limited
// on-board power", fig. 4). The caller supplies the path geometry (f', f'' and the cylinder
// arms at q): tip teleoperation builds it with TipPath, a prescribed joint path analytically.
//
//   sdot_d = min(request * tracking_factor, sdot_flow, sdot_cylinder, sdot_joint_limit,
//                sdot_power)                                   (uniform: direction kept)
//   [sddot_min, sddot_max] = power (LS or baseline) ∩ cylinder accelerations ∩ path acceleration
//   jerk-bounded filter -> s, sdot, sddot, sdddot
//
// A lower acceleration bound above zero is lowered to zero before the filter: no constraint
// may force the path to speed up (slowing down always lowers the pump flow).
//
// A failed dynamics step (RigidBodyTerms::path_terms: ODE out of memory) is a stop request, as
// a stale input is, within the bounds that need no dynamics (no power bound); it is reported
// (dynamics_failed, limit kDynamicsFailed) and the next cycle tries again.
//
// No allocation after construction, no exceptions (update() is noexcept), bounded work.
#pragma once

#include "craneassist/dynamics/path_terms.hpp"
#include "craneassist/scaling/path_constraints.hpp"
#include "craneassist/scaling/scaling_filter.hpp"

namespace craneassist::dynamics {
class RigidBodyTerms;
}

namespace craneassist::scaling {

struct PathScalerConfig {
  double period_s = 0.01;
  double jerk_max = 5.0;          // path jerk bound
  double acceleration_max = 1.0;  // path acceleration bound
  double flow_reserve = 0.0;      // share of the pump flow kept for feedback corrections
  PowerBound power_bound = PowerBound::kLoadSensing;
  double power_reserve = 0.0;     // share of P_max kept for feedback corrections
  double deceleration_max = 1.0;  // path deceleration bound
};

struct PathScalerInput {
  double sdot_request = 0.0;        // the operator's path speed (>= 0)
  double tracking_factor = 1.0;     // tracking-error slow-down delta(|e|), in (0, 1]
  double sdot_joint_limit = 1e300;  // end damping
  bool stale_input = false;         // the request is a stop because the input is not valid
};

struct PathScalerOutput {
  ScalingFilterState state;  // s, sdot, sddot, sdddot after this cycle
  ScalingFilterStatus filter_status = ScalingFilterStatus::kStopped;
  double sdot_d = 0.0;  // the prescaled speed request given to the filter
  SpeedLimits speed;
  AccelerationBounds bounds;
  dynamics::PathTerms terms;  // m(s), b(s) at the start of the cycle (zero: failed)
  ActiveLimit limit = ActiveLimit::kNone;
  bool dynamics_failed = false;  // this cycle's dynamics step failed: stopping without it
};

class PathScaler {
 public:
  // terms: the ODE dynamics probe of the same model; used every cycle, not owned.
  PathScaler(const dynamics::CraneModel& model, const PathScalerConfig& config,
             dynamics::RigidBodyTerms& terms);

  void reset(const ScalingFilterState& state = {});
  const ScalingFilterState& state() const { return filter_.state(); }
  const PathScalerConfig& config() const { return config_; }

  void update(const JointVector& q, const PathGeometry& geometry, const PathScalerInput& in,
              PathScalerOutput& out) noexcept;

 private:
  const dynamics::CraneModel& model_;
  PathScalerConfig config_;
  dynamics::RigidBodyTerms& terms_;
  ScalingFilter filter_;
  AccelerationLimits acceleration_limits_;
};

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
