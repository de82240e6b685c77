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
#include "craneassist/scaling/speed_caps.hpp"

namespace craneassist::dynamics {
class RigidBodyTerms;
}

namespace craneassist::paths {

using dynamics::JointVector;
using scaling::AccelerationBounds;
using scaling::AccelerationLimits;
using scaling::ActiveLimit;
using scaling::PathGeometry;
using scaling::PowerBound;
using scaling::ScalingFilter;
using scaling::ScalingFilterState;
using scaling::ScalingFilterStatus;
using scaling::SpeedLimits;

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

}  // namespace craneassist::paths
