// Jerk-bounded trajectory scaling filter (docs/algorithms.md section 5; "Real-time trajectory
// scaling algorithm for hydraulic manipulators subject to limited on-board power", appendix).
//
// The filter turns the prescaled path-speed request sdot_d and this cycle's path-acceleration
// bounds [sddot_min, sddot_max] into a path jerk j, |j| <= J, and integrates it exactly over the
// period T (piecewise-constant jerk):
//     sddot' = sddot + j T
//     sdot'  = sdot + sddot T + j T^2/2
//     s'     = s + sdot T + sddot T^2/2 + j T^3/6
//
// Origin. The paper adopts the filter of C. Guarino Lo Bianco & O. Gerelli, "Trajectory scaling
// for a manipulator inverse dynamics control subject to generalized force derivative
// constraints" (IROS 2009), which is built on the discrete-time sliding-mode law of R. Zanasi &
// R. Morselli, "Discrete minimum time tracking problem for a chain of three integrators with
// bounded input" (Automatica 2003), with two modifications: both acceleration bounds may have the
// same sign, and a zero command brings the motion to rest and holds it there. This is a
// look-ahead implementation with the same behaviour, not a transcription of their switching law
// (the paper's extracted formulas are garbled). The closed form below is the same staircase
// inversion as the paper's "m = floor((1 + sqrt(1 + 8|gamma|))/2)" step.
//
// The law, each cycle. Let a = sddot, v = sdot, x = the acceleration at the end of this step
// (so j = (x - a)/T). Braking from an acceleration x means bringing it to zero at full jerk in
// whole periods with a partial last period; it changes the velocity by
//     B(x) = braking_velocity_change(x, J, T)   (odd, increasing, continuous in x).
// The predicted final velocity after this step and such braking is
//     f(x) = v + T (a + x)/2 + B(x),
// which increases monotonically with x. The tracking choice is the x with f(x) = sdot_d:
// T x/2 + B(x) is piecewise linear in x, so x is found in closed form (no iteration). One more
// limit applies within a step of the target: if sdot_d is still ahead of sdot but f says "slow
// down", braking to zero acceleration would carry sdot past sdot_d on this very step, so the
// step instead lands sdot exactly on sdot_d and brakes through zero acceleration (when the jerk
// window allows; otherwise it brakes at full jerk). The tracking choice is then clamped, in this
// order of priority, to
//   1. the jerk window [a - J T, a + J T]        (|j| <= J, always),
//   2. the acceleration bounds [sddot_min, sddot_max], where they can be reached this step.
// If the bounds cannot be reached this step (sddot is outside them by more than J T), the step
// uses full jerk towards them; the step that can reach them lands on the violated bound (or
// further inside only when the tracking choice itself lies further inside).
//
// Guarantees.
//   - |jerk| <= J on every step, whatever the inputs (to floating-point rounding).
//   - Acceleration bounds: sddot outside [min, max] re-enters as fast as the jerk allows:
//     ceil(distance / (J T)) steps, landing on the bound. Once inside, sddot stays inside on
//     every step whose bounds moved by at most J T since the previous step (bound rate <= J);
//     the one exception is a zero command relaxing a bound that excludes rest (below).
//     Bounds of equal sign are legal: e.g. [-2, -0.5] makes the speed decrease on every step,
//     whatever sdot_d says (tracking sdot_d is then impossible and not attempted).
//   - No overshoot: with constant bounds that contain 0, the acceleration sequence chosen always
//     keeps a braking manoeuvre available whose final velocity is exactly f(x) (braking from x
//     at full jerk is again the same braking one step later), so f never passes sdot_d, and no
//     step carries the sampled sdot past it: sdot approaches sdot_d from one side only. If no
//     admissible jerk sequence can avoid passing sdot_d (the state is already too fast), sdot
//     passes it once, by no more than braking straight to zero acceleration would, and comes
//     back without passing it again.
//   - Minimum time: each step takes the largest jerk towards sdot_d that keeps that guarantee
//     (the discrete counterpart of the bang-bang time-optimal profile); the time to reach sdot_d
//     exceeds the continuous-time minimum by less than two periods (tested).
//   - Steady state: at sdot = sdot_d with sddot = 0 the jerk is exactly 0 and the state does not
//     change (no chattering). The last braking step lands exactly on (sdot_d, 0): residuals at
//     the rounding level are snapped.
//
// Zero command (sdot_d == 0, the paper's second modification). The motion comes to rest
// (sdot == 0 and sddot == 0 exactly, status kStopped) and stays there, regardless of the
// acceleration bounds. On the way, sdot does not change sign (unless no admissible jerk
// sequence can stop the state without doing so). The bounds are kept except where
// they contradict stopping, and then only as far as needed:
//   - a bound demanding deceleration also at rest (moving forward with sddot_max < 0, e.g. a
//     power bound that is negative at rest) is relaxed towards 0 only where keeping it would
//     carry sdot through zero (so the motion ends at rest instead of reversing);
//   - a bound forbidding deceleration altogether (moving forward with sddot_min >= 0) is dropped:
//     the stop then runs at the jerk limit only.
// (Mirror both for backward motion.) Safety first: at rest with a zero command the filter never
// starts moving, even if the bounds exclude zero acceleration.
//
// Conflicting constraints.
//   - Empty bounds (sddot_min > sddot_max): the LOWER of the two values is used as both bounds,
//     i.e. the filter decelerates (safety first).
//   - Bounds vs. tracking: bounds win; tracking sdot_d is then abandoned until they allow it.
//   - Jerk vs. bounds: the jerk bound wins; see the re-entry rule above.
//   - Non-finite inputs: a NaN or infinite sdot_d counts as a zero command (stop); a NaN bound is
//     ignored (that side unbounded); infinite bounds mean "unbounded".
//
// Real-time: no allocation, no exceptions, constant work per update.
#pragma once

namespace craneassist::scaling {

struct ScalingFilterConfig {
  double period_s;  // T > 0, the cycle time
  double jerk_max;  // J > 0, path jerk bound (path units/s^3)
};

struct ScalingFilterInput {
  double sdot_d;     // requested path speed (already prescaled); any sign; 0 = stop and hold
  double sddot_min;  // path acceleration bounds this cycle; may move every cycle; may both be
  double sddot_max;  // negative or both positive; if min > max, min(min, max) is used for both
};

struct ScalingFilterState {
  double s = 0, sdot = 0, sddot = 0, sdddot = 0;  // sdddot: the jerk applied in the last step
};

enum class ScalingFilterStatus {
  kTracking,             // free tracking of sdot_d (or holding it)
  kAccelerationLimited,  // an acceleration bound is what holds the jerk back this step
  kReenteringBounds,     // sddot is still outside the bounds after this step (full jerk);
                         // the step that lands on the bound reports kAccelerationLimited
  kStopped,              // at rest with a zero command
};

const char* to_string(ScalingFilterStatus status);

class ScalingFilter {
 public:
  // A config with a non-positive or non-finite period or jerk bound is a programming error: the
  // filter then never moves (update() keeps the state, jerk 0) and config_valid() is false.
  explicit ScalingFilter(const ScalingFilterConfig& config);

  // Non-finite fields of the state are replaced by 0.
  void reset(const ScalingFilterState& state = {});

  // Advances one period; out receives the new state (out.sdddot = the jerk of this step).
  ScalingFilterStatus update(const ScalingFilterInput& in, ScalingFilterState& out) noexcept;

  const ScalingFilterState& state() const { return state_; }
  const ScalingFilterConfig& config() const { return config_; }
  bool config_valid() const { return valid_; }

 private:
  ScalingFilterConfig config_;
  bool valid_;
  ScalingFilterState state_;
};

// Signed velocity change while bringing the acceleration sddot to zero at full jerk jerk_max in
// whole periods period_s, the last period partial (jerk -sddot_rest/T) so that the acceleration
// lands exactly on zero. With n = ceil(|sddot| / (J T)):
//     B = sign(sddot) T (|sddot|/2 + (n - 1)|sddot| - J T n (n - 1)/2)
// (= sddot T/2 for |sddot| <= J T). It equals sddot |sddot| / (2J) when |sddot| is a multiple of
// J T and is never less than it in magnitude. period_s <= 0 gives the continuous-time value
// sddot |sddot| / (2J); jerk_max <= 0 (or NaN) gives NaN.
double braking_velocity_change(double sddot, double jerk_max, double period_s);

// The largest speed v from which a stop with jerk <= jerk_max, deceleration <= decel_max and
// zero initial acceleration covers no more than `distance` (continuous time). When the stop
// reaches decel_max (v >= A^2/J) this is the root v >= 0 of
//     v^2/(2A) + v A/(2J) = d,
// otherwise (a triangular acceleration profile, v < A^2/J) it is v = cbrt(J d^2); the two agree
// at v = A^2/J, and the quadratic alone would understate v below it. decel_max = +inf gives the
// jerk-only value, jerk_max = +inf the classic sqrt(2 A d). Returns 0 for distance <= 0 and for
// non-positive or NaN arguments (no speed is safe then).
double max_speed_to_stop_within(double distance, double decel_max, double jerk_max);

// The distance a stop from speed v >= 0 and acceleration a covers when the acceleration is first
// brought to zero at full jerk (a > 0) and the stop_distance below follows; for a <= 0 the
// stop_distance from v (an upper bound). Continuous time.
double braking_distance(double speed, double acceleration, double decel_max, double jerk_max);

// Its inverse: the distance a stop from speed v with zero initial acceleration, jerk <= jerk_max
// and deceleration <= decel_max covers (continuous time): sqrt(v^3 / J) below v = A^2/J,
// v^2/(2A) + v A/(2J) above. 0 for v <= 0; +inf for non-positive or NaN limits.
double stop_distance(double speed, double decel_max, double jerk_max);

}  // namespace craneassist::scaling
