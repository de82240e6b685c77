// The grapple's swing period as a machine's swing sensor measures it (docs/sway.md, "Tuned to
// the measured swing"): the feedback that tunes the sway damping's shaper to the grapple the crane
// really carries, where the config's hanger, the rotator's geometry or a long log's inertia make
// the model's period wrong.
//
// Each of the sensor's two angles (towards the reach, across it) is watched for upward zero
// crossings, with hysteresis (the swing below -hysteresis before it counts again). The time
// between two crossings is a measured period when, over it, the swing went out at least
// min_amplitude each way (a real swing, not the sensor's noise) and the tip's reference kept still
// or at one velocity (its acceleration below free_acceleration: the grapple swung freely, not
// driven), and it lies within [min_ratio, max_ratio] of the model's period. What is kept is the
// ratio of the model's period at the time to the measured one, averaged over the last `periods`
// measurements: it carries over to other loads (a log grabbed changes the model's period; the
// model's error, a longer hanger, stays). No allocation, no exceptions; bounded work per cycle.
#pragma once

#include <array>
#include <cmath>
#include <limits>

namespace craneassist::scaling {

struct SwingFrequencySettings {
  double hysteresis_rad = 0.2 * M_PI / 180.0;
  double min_amplitude_rad = 0.5 * M_PI / 180.0;
  double free_acceleration_m_s2 = 0.05;
  double min_ratio = 0.5, max_ratio = 2.0;  // a measured period over the model's, plausible
  int periods = 2;                          // the newest measurements averaged (1..4)
};

class SwingFrequencyEstimator {
 public:
  explicit SwingFrequencyEstimator(const SwingFrequencySettings& settings = {});

  // Nothing measured.
  void reset() noexcept;

  // One cycle: the time, the sensor's two angles (NaN: not measured, the watch starts over), the
  // tip reference's acceleration and the model's swing period now (infinite: nothing hangs).
  void update(double t_s, double radial_rad, double tangential_rad, double acceleration_m_s2,
              double model_period_s) noexcept;

  // The model's period over the measured one (1 until a period was measured): the shaper's
  // frequency is the model's times this.
  double ratio() const noexcept;
  int measured() const noexcept { return count_; }  // periods measured so far
  double last_period_s() const noexcept { return last_period_s_; }

 private:
  struct Axis {
    double last_t = std::numeric_limits<double>::quiet_NaN(), last_x = 0.0;
    double up_t = std::numeric_limits<double>::quiet_NaN();  // the last upward crossing
    double high = 0.0, low = 0.0;                            // the swing's extremes since it
    bool armed = false;  // below -hysteresis since the last crossing
    bool free = false;   // no driving acceleration since it
  };
  void watch(Axis& a, double t, double x, bool driven, double model_period_s) noexcept;

  SwingFrequencySettings settings_;
  std::array<Axis, 2> axes_{};
  std::array<double, 4> ratios_{};
  int count_ = 0;
  double last_period_s_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace craneassist::scaling
