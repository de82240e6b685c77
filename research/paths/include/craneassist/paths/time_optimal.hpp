// The time-optimal traversal of a joint path q(s) under the limits the online scaler uses, and
// that scaler's own traversal of it: "as fast as the hydraulics allow" as a number.
//
// Bound: the phase-plane method of J. E. Bobrow, S. Dubowsky and J. S. Gibson, "Time-optimal
// control of robotic manipulators along specified paths" (IJRR 1985): integrate the squared
// path speed forward at the largest admissible acceleration (clipped to the speed caps) and
// backward from rest at the end at the largest deceleration; the minimum of the two is the
// fastest profile. The path is sampled every ds; at each sample and path speed the
// constraints are those of path_constraints.hpp with m(s), b(s) from the ODE model (the same
// functions the online scaler calls): pump flow and cylinder speeds (with the reserve), the
// load-sensing power bound on sddot, cylinder accelerations, the path acceleration and
// deceleration bounds, and an optional speed cap per sample (e.g. what an operator asked for).
// Between samples the acceleration is constant, admissible at the state it is taken from;
// dt = 2 ds / (sdot_k + sdot_k+1). No speed grid: the profile is exact to the sampling in s.
// The path jerk bound is not part of it (a (s, sdot) state cannot carry the acceleration): the
// bound is the acceleration-limited optimum, a lower bound for any jerk bound.
// An offline tool: it allocates, and throws std::runtime_error when a dynamics step fails.
#pragma once

#include <vector>

#include "craneassist/scaling/path_constraints.hpp"

namespace craneassist::dynamics {
class RigidBodyTerms;
}

namespace craneassist::paths {

using dynamics::JointVector;
using scaling::ActiveLimit;
using scaling::PathGeometry;
using scaling::PowerBound;

struct PathSample {
  double s = 0.0;  // path coordinate, m
  PathGeometry geometry;
  JointVector q;
  double sdot_cap = 1e300;       // an extra speed cap at this sample, m/s
  const char* cap_name = "cap";  // what it is, for reports ("turning", "operator request")
};

struct TimeOptimalSettings {
  double acceleration_max = 1.0;  // path
  double deceleration_max = 1.0;  // path
  double flow_reserve = 0.0;
  PowerBound power_bound = PowerBound::kLoadSensing;
  double power_reserve = 0.0;
};

// What holds the fastest profile back between two samples: a speed cap (pump flow, a
// cylinder's speed, or the sample's own cap: limit kNone), or the acceleration or deceleration
// bound (limit: kCylinderAcceleration, kPower, or kNone for the path's own bound).
enum class BoundPhase { kSpeedCap, kAccelerating, kDecelerating };

struct BoundSegment {
  BoundPhase phase = BoundPhase::kSpeedCap;
  ActiveLimit limit = ActiveLimit::kNone;
  double time_s = 0.0;
};

struct TimeOptimalResult {
  bool ok = false;  // a rest-to-rest traversal exists
  double time_s = 0.0;
  std::vector<double> sdot;            // per sample
  double top_speed = 0.0;              // highest speed cap anywhere
  std::vector<ActiveLimit> limit;      // which velocity-level cap is lowest at each sample
  std::vector<BoundSegment> segments;  // between samples k and k+1 (ok only)
  // Not ok: the first sample no admissible sequence from rest gets past (-1: none found), and the
  // largest path acceleration the constraints allow there at rest.
  int blocked_sample = -1;
  double blocked_acceleration_max = 0.0;
};

TimeOptimalResult time_optimal_profile(const dynamics::CraneModel& model,
                                       dynamics::RigidBodyTerms& terms,
                                       const std::vector<PathSample>& samples,
                                       const TimeOptimalSettings& settings);

}  // namespace craneassist::paths
