// The scaling of tip teleoperation: the reference tip velocity, a vector, moved each cycle towards
// the operator's command scaled by one factor, along the straight segment between them.
//
// Each cycle:
//   1. The path runs along u, the direction of the present reference velocity v (at rest: the
//      command's). TipPath resolves u into f', f''.
//   2. Velocity-level limits along u (pump flow, cylinder speeds, quasi-static power, path
//      curvature, end damping, tracking error; lowest_speed_cap) give one factor k <= 1 on the
//      whole command: the target is c* = k c, so the tip keeps the commanded direction.
//   3. The reference velocity moves from v towards c* along the segment between them, as a
//      jerk-limited scalar motion along e = (c* - v)/|c* - v| (the ScalingFilter: minimum time,
//      no overshoot, acceleration inside moving bounds); Ruckig calls this phase
//      synchronisation. A turn therefore rounds inside the plane of the two commands. A reversal
//      (the segment passes through rest, or within 5 % of the speed of it) decelerates to rest on
//      the line, acceleration included, and accelerates back along it. Acceleration left over
//      from an earlier segment, across the new one, is brought to zero at half the jerk bound.
//      Cylinder speeds are read ahead: where a joint's rate per metre grows along the path (f',
//      f'' of the same sign; near a singular pose without bound), the cap is taken where a
//      brake would take effect, after the acceleration has swung to full deceleration.
//   4. The acceleration along e is bounded so that the tangential part (along u) stays within the
//      path's acceleration bounds (the load-sensing power limit with m(s), b(s) from the ODE
//      model, cylinder accelerations, path acceleration and deceleration; path_constraints.hpp)
//      and the normal part within normal_acceleration_max.
//
// A stale input stops along the present direction (target 0) within the same bounds; at rest
// with a zero target the reference stays exactly at rest. A failed dynamics step (the ODE step of
// RigidBodyTerms::path_terms, out of memory) stops the same way, within the bounds that need no
// dynamics (cylinder accelerations, the path's acceleration and deceleration; no power bound),
// and is reported (dynamics_failed, limit kDynamicsFailed); the next cycle tries again. No
// allocation, no exceptions (update() is noexcept), bounded work per cycle.
#pragma once

#include <Eigen/Core>

#include "craneassist/dynamics/path_terms.hpp"
#include "craneassist/scaling/path_constraints.hpp"
#include "craneassist/scaling/scaling_filter.hpp"
#include "craneassist/scaling/speed_caps.hpp"
#include "craneassist/scaling/sway_shaper.hpp"

namespace craneassist::dynamics {
class RigidBodyTerms;
}

namespace craneassist::scaling {

struct TipScalerConfig {
  double period_s = 0.01;
  double jerk_max = 5.0;                 // tip jerk bound, m/s^3
  double acceleration_max = 1.0;         // path acceleration, m/s^2
  double deceleration_max = 1.0;         // path deceleration, m/s^2
  double normal_acceleration_max = 0.6;  // tip acceleration across u (turning), m/s^2
  double flow_reserve = 0.0;
  PowerBound power_bound = PowerBound::kLoadSensing;
  double power_reserve = 0.0;
  // The longest sway-shaping delay kept (half the slowest swing period; sway_shaper.hpp).
  double sway_max_delay_s = 3.0;
};

struct TipScalerInput {
  Eigen::Vector3d command = Eigen::Vector3d::Zero();     // finite, m/s; zero: stop
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // u this cycle (direction())
  double tracking_factor = 1.0;
  double sdot_joint_limit = 1e300;  // end damping along u
  // Path length left before a joint end along u, and the stop a brake there may use
  // (TipPathOutput): the scaler brakes when a stop from its speed and acceleration needs it.
  double end_distance_m = 1e300;
  double stop_deceleration_m_s2 = 1.0;
  double stop_jerk_m_s3 = 1.0;
  bool near_singular = false;
  bool stale_input = false;
  // The rated capacity limiter refuses motion along u (it would raise the load moment of an
  // overloaded crane): the target is rest, reached within the jerk and deceleration bounds
  // (limit kOverload).
  bool overload_refused = false;
  // Sway damping (docs/sway.md): the hanging grapple's natural frequency and damping ratio; the
  // reference velocity is the scaler's motion ZV-shaped to them (SwayShaper). 0: no shaping. A
  // stop (stale input, failed dynamics), the brake at a joint end and the limiter's refusal are
  // not shaped: the motion takes over from the shaped reference and acts at once.
  double sway_omega_rad_s = 0.0;
  double sway_zeta = 0.0;
};

struct TipScalerOutput {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      // after this cycle, m/s
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  // after this cycle, m/s^2
  double ds = 0.0;            // tip displacement along u this cycle (signed), m
  double s = 0.0;             // path length covered since reset, m
  double sdot = 0.0;          // |velocity|
  double sddot = 0.0;         // acceleration along the velocity's direction
  double sdddot = 0.0;        // |jerk| of this cycle
  double target_speed = 0.0;  // |c*|: the scaled command speed
  double scale = 1.0;         // k = |c*| / |c| (1 without a command)
  SpeedLimits speed;
  AccelerationBounds bounds;
  dynamics::PathTerms terms;  // m(s), b(s) along u at the start of the cycle (zero: failed)
  ActiveLimit limit = ActiveLimit::kNone;
  bool at_rest = true;           // velocity and acceleration exactly zero
  bool dynamics_failed = false;  // this cycle's dynamics step failed: stopping without it
};

class TipScaler {
 public:
  // terms: the ODE dynamics probe of the same model; used every cycle, not owned.
  TipScaler(const dynamics::CraneModel& model, const TipScalerConfig& config,
            dynamics::RigidBodyTerms& terms);

  // At rest.
  void reset();

  // The direction the path runs along this cycle: the present velocity's, or at rest the
  // command's (or the last direction without a command).
  Eigen::Vector3d direction(const Eigen::Vector3d& command) const;
  // The speed the motion heads for with this command: the bounds of the redundancy resolution
  // are shaped for it (ahead of the present speed by a margin, never beyond the command).
  double intended_speed(const Eigen::Vector3d& command) const;
  // The reference's speed and velocity (shaped when the sway damping shapes it).
  double speed() const { return ref_velocity_.norm(); }
  const Eigen::Vector3d& velocity() const { return ref_velocity_; }

  // geometry: TipPath's resolution of in.direction at q.
  void update(const JointVector& q, const PathGeometry& geometry, const TipScalerInput& in,
              TipScalerOutput& out) noexcept;

 private:
  // The lowest cylinder-speed cap ahead along the path (see the header comment), m/s.
  double cylinder_speed_ahead(const PathGeometry& g, double speed, double acceleration) const;

  const dynamics::CraneModel& model_;
  TipScalerConfig config_;
  dynamics::RigidBodyTerms& terms_;
  AccelerationLimits acceleration_limits_;
  Eigen::Vector3d velocity_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d acceleration_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_direction_ = Eigen::Vector3d::UnitX();
  double s_ = 0.0;
  bool reversing_ = false;    // coming to rest before leaving the other way
  bool end_brake_ = false;    // braked at a joint end, holding until the end damping frees it
  double rest_time_s_ = 0.0;  // at rest since the brake
  Eigen::Vector3d end_brake_command_ = Eigen::Vector3d::Zero();
  // Sway damping: velocity_ and acceleration_ are the motion the limits shape; the reference is
  // that motion ZV-shaped (SwayShaper) while shaping_, the motion itself otherwise.
  void hand_over();
  // The shaper's past from the motion's present state (re-entry after a hand-over); false when
  // no such past keeps the jerk bound (the motion accelerates too hard).
  bool seed_shaper_past(const Eigen::Vector3d& v, const Eigen::Vector3d& a);
  static constexpr long kSteadyForever = 1L << 30;
  SwayShaper velocity_shaper_, acceleration_shaper_;
  Eigen::Vector3d ref_velocity_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d ref_acceleration_ = Eigen::Vector3d::Zero();
  bool shaping_ = false;
  long steady_cycles_ = kSteadyForever;
  long since_hand_over_ = kSteadyForever;
  bool held_back_ = false;                           // last cycle: a limit held the motion back
  double sway_omega_rad_s_ = 0.0, sway_zeta_ = 0.0;  // latched while shaping
};

}  // namespace craneassist::scaling
