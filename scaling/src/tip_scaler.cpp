#include "craneassist/scaling/tip_scaler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "craneassist/dynamics/hydraulics.hpp"

namespace craneassist::scaling {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kSegmentEpsilon = 1e-12;  // m/s: a target this close is reached
// The scalar filter runs on progress along the segment offset by this, so that its target is
// never zero (a zero target means "stop" to the filter, here it means "arrived").
constexpr double kProgressOffset = 1.0;
// The intended speed runs ahead of the present one by this much (and this share).
constexpr double kIntendedMargin = 0.2;
constexpr double kIntendedShare = 1.25;
// A change of command whose straight segment passes this close to rest (share of the larger
// speed) is a reversal.
constexpr double kReversalShare = 0.05;
// After braking at a joint end: restart once the end damping allows this share of the request
// (as far as the hydraulics give it)
// (at least kRestartSpeed), or when the command changes by more than kCommandChange of itself.
constexpr double kRestartShare = 0.3;
constexpr double kRestartSpeed = 0.05;  // m/s
constexpr double kCommandChange = 0.02;
constexpr double kMinRestTime = 0.4;  // s: valve delay and lag with margin
constexpr double kRestartRoom = 4.0;
constexpr double kMinRestartRoom = 0.1;  // m: a restart from rest goes at least this far
// m/s^2: the shaped reference's acceleration may pass a bound by this before the motion takes
// over (rounding).
constexpr double kBoundSlack = 1e-9;
// And by this share of the bound: the bounds vary with the path speed (the cylinder accelerations
// through f'' sdot^2), so a blend of two motions, each within the bound at its own speed, is
// within the bound at the blended speed to about this (measured: 8e-6 of a cylinder-acceleration
// bound at the start of a loaded lift).
constexpr double kBoundShare = 1e-4;
double slack(double bound) {
  return kBoundSlack + kBoundShare * std::abs(bound);
}

}  // namespace

TipScaler::TipScaler(const dynamics::CraneModel& model, const TipScalerConfig& config,
                     dynamics::RigidBodyTerms& terms)
    : model_(model),
      config_(config),
      terms_(terms),
      velocity_shaper_(config.period_s, config.sway_max_delay_s),
      acceleration_shaper_(config.period_s, config.sway_max_delay_s) {
  acceleration_limits_.path_acceleration_max = config.acceleration_max;
  acceleration_limits_.power_bound = config.power_bound;
  acceleration_limits_.power_reserve = config.power_reserve;
  acceleration_limits_.path_deceleration_max = config.deceleration_max;
}

void TipScaler::reset() {
  velocity_.setZero();
  acceleration_.setZero();
  reversing_ = false;
  end_brake_ = false;
  s_ = 0.0;
  velocity_shaper_.reset();
  acceleration_shaper_.reset();
  ref_velocity_.setZero();
  ref_acceleration_.setZero();
  shaping_ = false;
  steady_cycles_ = kSteadyForever;
  since_hand_over_ = kSteadyForever;
  held_back_ = false;
}

void TipScaler::hand_over() {
  // The motion's own state becomes the reference's: continuous in velocity and acceleration.
  velocity_ = ref_velocity_;
  acceleration_ = ref_acceleration_;
  shaping_ = false;
  steady_cycles_ = 0;
}

bool TipScaler::seed_shaper_past(const Eigen::Vector3d& v, const Eigen::Vector3d& a) {
  // The past the coming shape() calls blend with, a window of T = n periods, from the state this
  // cycle starts from, (v, a): it starts there (so the shaped reference starts on the motion) and
  // ends where the motion will be when the recorded motion takes over, v + a dt after T, with the
  // acceleration a at both ends (so the past goes on continuously). The least jerk that does it:
  // the acceleration swings from a to -a and back at the jerk 4 |a| / T (the velocity |a| T / 8
  // ahead of v along a and as far back), plus the one period's a dt spread over the middle,
  // h'(tau) = a (1 - 4 m / T) + (a dt / T) 4 m / T, m = min(tau, T - tau). Seeded only where
  // that keeps the jerk bound (|a| <= J T / 4) and leaves the past's velocity at least half the
  // present one (never through rest: a motion near the end of a stop is not shaped); otherwise
  // false, and shaping waits.
  const std::size_t n = velocity_shaper_.window(sway_omega_rad_s_, sway_zeta_);
  const double dt = config_.period_s;
  const double span = static_cast<double>(n) * dt;
  if (n == 0 || 4.0 * a.norm() > config_.jerk_max * span ||
      a.norm() * span / 8.0 > 0.5 * v.norm() + kSegmentEpsilon) {
    return false;
  }
  const auto accel = [&](std::size_t k) {
    const double tau = static_cast<double>(k) * dt;
    const double m = 4.0 * std::min(tau, span - tau) / span;
    return Eigen::Vector3d(a * (1.0 - m + m * dt / span));
  };
  Eigen::Vector3d h = v;
  for (std::size_t k = 0; k < n; ++k) {
    velocity_shaper_.set_upcoming_past(k, h, sway_omega_rad_s_, sway_zeta_);
    acceleration_shaper_.set_upcoming_past(k, accel(k), sway_omega_rad_s_, sway_zeta_);
    h += 0.5 * dt * (accel(k) + accel(k + 1));
  }
  return true;
}

Eigen::Vector3d TipScaler::direction(const Eigen::Vector3d& command) const {
  // The reference's own velocity (shaped), else the motion's that leads it.
  for (const Eigen::Vector3d* v : {&ref_velocity_, &velocity_}) {
    const double speed = v->norm();
    if (speed > 0.0) return *v / speed;
  }
  for (const Eigen::Vector3d* a : {&ref_acceleration_, &acceleration_}) {
    const double accel = a->norm();
    if (accel > 0.0) return *a / accel;  // leaving rest (a reversal through zero)
  }
  const double c = command.norm();
  if (c > 0.0 && std::isfinite(c)) return command / c;
  return last_direction_;
}

double TipScaler::intended_speed(const Eigen::Vector3d& command) const {
  const double speed = std::max(velocity_.norm(), ref_velocity_.norm());
  const double c = command.allFinite() ? command.norm() : 0.0;
  return std::max(speed, std::min(c, std::max(kIntendedShare * speed, speed + kIntendedMargin)));
}

double TipScaler::cylinder_speed_ahead(const PathGeometry& g, double speed,
                                       double acceleration) const {
  auto cap_at = [&](double x) {  // the lowest growing cylinder cap x metres ahead
    double cap = kInf;
    for (int i = 0; i < model_.dof(); ++i) {
      const double rate = g.f1[i];
      if (!(rate * g.f2[i] > 0.0)) continue;  // not growing along the path
      const double v_max = dynamics::cylinder_speed_cap_m_s(
          model_.cylinders[static_cast<std::size_t>(i)], config_.flow_reserve);
      cap =
          std::min(cap, v_max / (std::abs(g.dc_dq[i]) * (std::abs(rate) + std::abs(g.f2[i]) * x)));
    }
    return cap;
  };
  // The path length a slow-down from the present speed and acceleration to the cap needs: the
  // swing of the acceleration to full deceleration at the jerk bound, then the deceleration, plus
  // two cycles. The cap is read there; a few fixed-point steps settle the distance.
  const double decel = config_.deceleration_max, jerk = config_.jerk_max;
  const double swing = (std::max(acceleration, 0.0) + decel) / jerk;
  double cap = cap_at(0.0);
  if (!std::isfinite(cap)) return cap;
  double ahead = cap;
  for (int k = 0; k < 3; ++k) {
    const double slow_down = std::max(speed * speed - ahead * ahead, 0.0) / (2.0 * decel);
    ahead = cap_at(speed * (swing + 2.0 * config_.period_s) + slow_down);
  }
  return std::min(cap, ahead);
}

void TipScaler::update(const JointVector& q, const PathGeometry& geometry, const TipScalerInput& in,
                       TipScalerOutput& out) noexcept {
  const double period = config_.period_s;
  const double jerk = config_.jerk_max;
  const Eigen::Vector3d& u = in.direction;
  double speed = velocity_.norm();
  // What acts at once takes the motion over from where the shaped reference is, unshaped.
  const auto take_over = [&] {
    if (!shaping_) return;
    hand_over();
    speed = velocity_.norm();
  };
  // A stop and the load limiter's refusal.
  if (in.stale_input || in.overload_refused) take_over();

  // Velocity-level limits along u and the acceleration bounds at the present speed. Without the
  // dynamics (a failed step) the bounds are those that need none: no power bound.
  path_speed_limits(model_, geometry, config_.flow_reserve, out.speed);
  out.dynamics_failed = !path_terms_and_bounds(model_, terms_, q, geometry, speed,
                                               acceleration_limits_, out.terms, out.bounds);
  // A stale input or a failed dynamics step: a jerk-limited stop along the present direction.
  const bool stop = in.stale_input || out.dynamics_failed;
  if (stop) take_over();
  // Sway damping starts again (see below) before this cycle's motion: on the state the cycle
  // starts from, the motion's and the reference's alike (not shaping), so this cycle's change is
  // the first to be shaped and its limits the tightened ones.
  const long window =
      std::lround(SwayShaper::delay_s(in.sway_omega_rad_s, in.sway_zeta) / period) + 1;
  if (!shaping_ && in.sway_omega_rad_s > 0.0 && !stop && !in.overload_refused && !end_brake_ &&
      !reversing_ && since_hand_over_ >= window && (steady_cycles_ >= window || !held_back_)) {
    const double omega = sway_omega_rad_s_, zeta = sway_zeta_;
    sway_omega_rad_s_ = in.sway_omega_rad_s;
    sway_zeta_ = in.sway_zeta;
    shaping_ = steady_cycles_ >= window || seed_shaper_past(velocity_, acceleration_);
    if (!shaping_) {
      sway_omega_rad_s_ = omega;  // as it was (no shaping: the history goes on recording)
      sway_zeta_ = zeta;
    }
  }

  // One factor on the whole command.
  const double request = in.command.norm();
  SpeedCap cap = lowest_speed_cap(request, in.tracking_factor, in.sdot_joint_limit, out.speed,
                                  out.bounds, in.near_singular);
  const double ahead = cylinder_speed_ahead(geometry, speed, acceleration_.dot(u));
  if (ahead < cap.value) {
    cap = {ahead, in.near_singular ? ActiveLimit::kSingularity : ActiveLimit::kCylinderSpeed};
  }
  if (in.overload_refused) cap = {0.0, ActiveLimit::kOverload};
  double target = stop ? 0.0 : std::clamp(cap.value, 0.0, request);
  // The lowest of this cycle's velocity-level limits whatever the stick asks (out.bounds as they
  // stand when called).
  const auto physical_cap = [&] {
    return std::min(
        lowest_speed_cap(kInf, 1.0, in.sdot_joint_limit, out.speed, out.bounds, in.near_singular)
            .value,
        ahead);
  };
  // While the reference is shaped, (v + K v_past) / (1 + K), the motion's own limits are those
  // that keep the shaped reference within this cycle's: |v| <= (1 + K) cap - K |v_past| under a
  // speed cap, and the same on the acceleration bounds below.
  double k_past = 0.0;
  Eigen::Vector3d v_past = Eigen::Vector3d::Zero(), a_past = Eigen::Vector3d::Zero();
  if (shaping_) {
    k_past = SwayShaper::past_weight(sway_zeta_);
    v_past = velocity_shaper_.upcoming_past(sway_omega_rad_s_, sway_zeta_);
    a_past = acceleration_shaper_.upcoming_past(sway_omega_rad_s_, sway_zeta_);
    const double physical = physical_cap();
    if (std::isfinite(physical)) {
      target = std::min(target, std::max((1.0 + k_past) * physical - k_past * v_past.norm(), 0.0));
    }
  }
  // Braking trigger at a joint end: the end damping cap assumes braking from zero acceleration;
  // while the path still accelerates, braking must begin earlier.
  // Once braked there, the reference stays at rest until the end damping would allow a useful
  // speed again or the stick moves elsewhere: no creeping in stop-and-go steps, which makes the
  // valves chatter through their dead zones.
  // The reference (shaped or not) is what approaches the end.
  const double ref_speed = ref_velocity_.norm();
  if (ref_speed > 0.0 &&
      braking_distance(ref_speed, ref_acceleration_.dot(u), in.stop_deceleration_m_s2,
                       in.stop_jerk_m_s3) >= in.end_distance_m) {
    take_over();
    end_brake_ = true;
    rest_time_s_ = 0.0;
    end_brake_command_ = in.command;
  } else if (end_brake_) {
    // Having come to rest, it stays there long enough for the valves to settle (a restart right
    // after the stop, with the machine still moving, would swing spools across their dead
    // zones).
    rest_time_s_ = speed == 0.0 ? rest_time_s_ + period : 0.0;
    // A share of what the stick asks for as far as the hydraulics give it (a stick pushed
    // beyond what the crane can do does not raise the bar).
    const double reachable =
        std::min(request, lowest_speed_cap(request, 1.0, kInf, out.speed, out.bounds, false).value);
    const double restart = std::max(kRestartShare * reachable, kRestartSpeed);
    const bool moved = (in.command - end_brake_command_).norm() > kCommandChange * request;
    const bool settled = speed > 0.0 || rest_time_s_ >= kMinRestTime;
    // Nearly at rest, only where a restart can go somewhere: a stop from the restart speed fits
    // kRestartRoom times into what is left to the end, and that is at least kMinRestartRoom. At the
    // workspace's end the null space moves the joints' ends about and the end damping's cap rises
    // and falls; without this the reference braked, restarted at a few cm/s and braked again, twice
    // within a second. Still moving at the restart speed, the end damping's cap takes over as soon
    // as it allows that speed (a hand-over moving the end away).
    const bool room =
        speed >= restart ||
        std::max(kRestartRoom *
                     braking_distance(restart, 0.0, in.stop_deceleration_m_s2, in.stop_jerk_m_s3),
                 kMinRestartRoom) < in.end_distance_m;
    if ((in.sdot_joint_limit >= restart && room && settled) || moved || request == 0.0) {
      end_brake_ = false;
    }
  }
  const bool end_brake = end_brake_;
  if (end_brake) target = 0.0;
  Eigen::Vector3d goal =
      request > 0.0 ? Eigen::Vector3d(in.command * (target / request)) : Eigen::Vector3d::Zero();
  out.target_speed = target;
  out.scale = request > 0.0 ? target / request : 1.0;

  // A reversal (the segment to the goal passes through rest, or within kReversalShare of it)
  // comes to rest first, acceleration included, and leaves towards the goal from rest: every
  // valve then crosses its dead zone at rest instead of at full deceleration.
  if (speed > 0.0 && !reversing_) {
    const Eigen::Vector3d span = goal - velocity_;
    const double span2 = span.squaredNorm();
    const double t = span2 > 0.0 ? std::clamp(-velocity_.dot(span) / span2, 0.0, 1.0) : 0.0;
    const double closest = (velocity_ + t * span).norm();
    reversing_ =
        goal.dot(velocity_) < 0.0 && closest < kReversalShare * std::max(speed, goal.norm());
  }
  if (reversing_) {
    goal.setZero();
    // A reversal is not shaped: it comes to rest first, and every valve crosses its dead zone
    // at rest (a shaped reference would pass through zero still decelerating).
    take_over();
  }

  // The segment from the present velocity to the goal.
  Eigen::Vector3d d = goal - velocity_;
  double distance = d.norm();
  const double accel = acceleration_.norm();
  Eigen::Vector3d v_new = velocity_, a_new = acceleration_;
  ScalingFilterStatus status = ScalingFilterStatus::kTracking;
  if (distance == 0.0 && accel == 0.0) {
    status = ScalingFilterStatus::kStopped;  // holding: nothing changes
  } else {
    Eigen::Vector3d e;
    if (distance > kSegmentEpsilon) {
      e = d / distance;
    } else {
      distance = 0.0;
      e = accel > 0.0 ? Eigen::Vector3d(-acceleration_ / accel) : u;
    }
    const double a_par = acceleration_.dot(e);
    const Eigen::Vector3d a_perp = acceleration_ - a_par * e;
    const double perp = a_perp.norm();
    const double perp_step = std::min(perp, 0.5 * jerk * period);
    const Eigen::Vector3d a_perp_new = perp > perp_step
                                           ? Eigen::Vector3d(a_perp * (1.0 - perp_step / perp))
                                           : Eigen::Vector3d::Zero();

    // Bounds on the acceleration along e: its tangential part within the path's bounds (no
    // constraint may force the path to speed up or keep it from stopping), its normal part
    // within the turning limit.
    double lo = -kInf, hi = kInf;
    const double eu = e.dot(u);
    const double perp_u = a_perp_new.dot(u);
    double s_min = stop_bound(out.bounds, acceleration_limits_.path_deceleration_max);
    double s_max = out.bounds.sddot_max;
    if (shaping_) {
      const double past_along = a_past.dot(u);
      s_min = (1.0 + k_past) * s_min - k_past * past_along;
      s_max = (1.0 + k_past) * s_max - k_past * past_along;
    }
    if (std::abs(eu) > 1e-9) {
      double t1 = (s_min - perp_u) / eu, t2 = (s_max - perp_u) / eu;
      if (std::isnan(t1)) t1 = -kInf;
      if (std::isnan(t2)) t2 = kInf;
      lo = std::min(t1, t2);
      hi = std::max(t1, t2);
    }
    const double en = (e - eu * u).norm();
    if (en > 1e-9) {
      const double h = config_.normal_acceleration_max / en;
      lo = std::max(lo, -h);
      hi = std::min(hi, h);
    }
    // Nothing may push the velocity past its goal: a bound that asks for more acceleration
    // towards the goal than zero (the power bound asking for deceleration while the reference
    // comes to rest, possibly beyond what the other bounds allow) yields to landing on it
    // without overshoot; a stop never turns into a reversal.
    lo = std::min(lo, 0.0);
    hi = std::max(hi, lo);

    // Jerk-limited scalar motion along the segment.
    const double jerk_par =
        std::sqrt(std::max(jerk * jerk - (perp_step / period) * (perp_step / period), 0.0));
    ScalingFilter filter(ScalingFilterConfig{period, jerk_par > 0.0 ? jerk_par : jerk});
    filter.reset({0.0, kProgressOffset, a_par, 0.0});
    ScalingFilterState st;
    const double goal_progress = kProgressOffset + distance;
    status = filter.update({goal_progress, lo, hi}, st);
    const double progress = st.sdot - kProgressOffset;
    v_new = velocity_ + progress * e + 0.5 * period * (a_perp + a_perp_new);
    a_new = st.sddot * e + a_perp_new;
    if (st.sdot == goal_progress && st.sddot == 0.0 && a_perp_new.isZero(0.0)) {
      v_new = goal;  // arrived: exactly on the goal, at rest when the goal is zero
      a_new.setZero();
    }
  }

  const bool moved = !(v_new == velocity_ && a_new.isZero(0.0));
  velocity_ = v_new;
  acceleration_ = a_new;
  const bool motion_at_rest = v_new.isZero(0.0) && a_new.isZero(0.0);
  if (motion_at_rest) reversing_ = false;

  // Sway damping (docs/sway.md): the reference is the motion ZV-shaped to the grapple's swing.
  // A stop, the end brake, the limiter's refusal and a reversal hand the shaped state back to
  // the motion (hand_over). Shaping takes a new frequency only when the motion has been steady
  // for longer than the shaper's delay (its history is flat, so the shaped reference does not
  // jump). It starts again as soon as none of those acts (after a limit the shaped reference
  // would pass, half a swing period later), on a motion that no limit holds back, whatever the
  // motion does then (a stick that keeps moving, an arc): the shaper's past is replaced by one
  // that starts and ends on the motion as it is now (seed_shaper_past), so the shaped reference
  // starts on the motion, continuous, and blends two motions within the bounds. What the motion
  // does from then on is shaped; the swing the unshaped part started is not cancelled.
  const bool hard = stop || end_brake_ || in.overload_refused || reversing_;
  // A limit holds the motion back: the power or pressure bound it accelerates against, or a
  // velocity-level limit below the request (what out.limit reports, below). Shaping does not
  // start again into it (next cycle).
  held_back_ = (status == ScalingFilterStatus::kAccelerationLimited &&
                (out.bounds.limit_max == ActiveLimit::kPower ||
                 out.bounds.limit_max == ActiveLimit::kPressure) &&
                a_new.dot(u) >= out.bounds.sddot_max - 1e-9) ||
               (cap.kind != ActiveLimit::kNone && cap.value < request);
  if (!hard && steady_cycles_ >= window) {
    shaping_ = in.sway_omega_rad_s > 0.0;
    sway_omega_rad_s_ = in.sway_omega_rad_s;
    sway_zeta_ = in.sway_zeta;
  }
  steady_cycles_ = moved ? 0 : std::min(steady_cycles_ + 1, kSteadyForever);
  since_hand_over_ = std::min(since_hand_over_ + 1, kSteadyForever);
  const Eigen::Vector3d v_ref = velocity_shaper_.shape(v_new, sway_omega_rad_s_, sway_zeta_);
  const Eigen::Vector3d a_ref = acceleration_shaper_.shape(a_new, sway_omega_rad_s_, sway_zeta_);
  const Eigen::Vector3d v_out = shaping_ ? v_ref : v_new;
  const Eigen::Vector3d a_out = shaping_ ? a_ref : a_new;
  // The shaped reference within the limits at its own speed: the speed caps of this cycle (a
  // blend with the speed of half a period ago passes a cap that has fallen since) and the
  // acceleration bounds (the power bound is not convex in speed and acceleration). The cycle
  // that passes one (by no more than it moved since the last) hands the shaped state to the
  // motion, which brings it back within the jerk bound as it follows any moving limit.
  bool past_bounds = false;
  if (shaping_ && !(v_out == v_new && a_out == a_new)) {
    const double ref_speed_out = v_out.norm();
    const bool dynamics_ok = path_terms_and_bounds(model_, terms_, q, geometry, ref_speed_out,
                                                   acceleration_limits_, out.terms, out.bounds);
    const double speed_cap = physical_cap();
    const double along = a_out.dot(u);
    const double lowest = stop_bound(out.bounds, acceleration_limits_.path_deceleration_max);
    past_bounds = !dynamics_ok || ref_speed_out > speed_cap + kBoundSlack ||
                  along > out.bounds.sddot_max + slack(out.bounds.sddot_max) ||
                  along < lowest - slack(lowest);
  }

  const Eigen::Vector3d step = 0.5 * period * (ref_velocity_ + v_out);
  out.ds = step.dot(u);
  s_ += step.norm();
  out.s = s_;
  out.sdddot = (a_out - ref_acceleration_).norm() / period;
  ref_velocity_ = v_out;
  ref_acceleration_ = a_out;
  out.velocity = v_out;
  out.acceleration = a_out;
  out.sdot = v_out.norm();
  if (out.sdot > 0.0) last_direction_ = v_out / out.sdot;
  out.sddot = a_out.dot(out.sdot > 0.0 ? last_direction_ : u);
  out.at_rest = motion_at_rest && v_out.isZero(0.0) && a_out.isZero(0.0);
  if (past_bounds) {
    // Shaping starts again no sooner than half a swing period later (not at once into the same
    // limit).
    hand_over();
    since_hand_over_ = 0;
  }

  // What holds the motion back: the failed dynamics, the stale input, a power bound the
  // tangential acceleration is pressed against, or the lowest velocity-level limit when it is
  // below the request.
  out.limit = ActiveLimit::kNone;
  if (out.dynamics_failed) {
    out.limit = ActiveLimit::kDynamicsFailed;
  } else if (in.stale_input) {
    out.limit = ActiveLimit::kStaleInput;
  } else if (status == ScalingFilterStatus::kAccelerationLimited &&
             (out.bounds.limit_max == ActiveLimit::kPower ||
              out.bounds.limit_max == ActiveLimit::kPressure) &&
             a_new.dot(u) >= out.bounds.sddot_max - 1e-9) {
    out.limit = out.bounds.limit_max;
  } else if (end_brake) {
    out.limit = ActiveLimit::kJointLimit;
  } else if (cap.kind != ActiveLimit::kNone && cap.value < request) {
    out.limit = cap.kind;
  }
}

}  // namespace craneassist::scaling
