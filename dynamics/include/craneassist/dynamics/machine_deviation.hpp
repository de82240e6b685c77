// How a machine differs from the controller's model where real machines do
// (docs/valves.md#the-machine-it-meets): its valve sections' spools are faster or slower, later,
// with other dead bands, gains and characteristic shapes and some hysteresis; its joint sensors
// are noisy, coarse and late, and the feedback reaches the controller over a bus with its own
// delay and jitter. The simulator's machine reads these from the crane config's `simulation`
// section (simulation.valves, simulation.joint_sensors, simulation.feedback); the controller
// never does.
#pragma once

#include <array>
#include <cmath>
#include <limits>

#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

// One valve section as the machine has it. NaN: the model's value (hydraulics.valves).
struct ValveDeviation {
  double time_constant_s = std::numeric_limits<double>::quiet_NaN();
  double delay_s = std::numeric_limits<double>::quiet_NaN();
  double dead_zone = std::numeric_limits<double>::quiet_NaN();  // start current, share of range
  // The steady cylinder velocity at every opening times this (the whole characteristic scaled).
  double gain = 1.0;
  // Beyond the dead band the velocity follows opening^shape (1: the model's straight line; 2: a
  // progressive spool, slow at small openings; 0.5: a degressive one).
  double shape = 1.0;
  // The spool's hysteresis (play) in command units: a reversing command moves the effective
  // spool only after it has come back this far.
  double hysteresis = 0.0;
};

using ValveDeviations = std::array<ValveDeviation, kMaxJoints>;

// The joint position sensors and the feedback path as the machine has them. Every reading is
// delayed by delay_s + feedback_delay_s plus a uniform jitter in [0, feedback_jitter_s), then
// gets white noise of the standard deviation and is rounded to the resolution (each 0: none).
// The rates the machine reports are those of the delayed reading (without the noise).
struct JointSensing {
  double angle_noise_rad = 0.0;
  double angle_resolution_rad = 0.0;
  double length_noise_m = 0.0;
  double length_resolution_m = 0.0;
  double delay_s = 0.0;           // the sensors' own (filtering, sampling)
  double feedback_delay_s = 0.0;  // transport to the controller (a bus)
  double feedback_jitter_s = 0.0;
  bool exact() const {
    return angle_noise_rad == 0.0 && angle_resolution_rad == 0.0 && length_noise_m == 0.0 &&
           length_resolution_m == 0.0 && delay_s == 0.0 && feedback_delay_s == 0.0 &&
           feedback_jitter_s == 0.0;
  }
};

// The machine's section: the model's valve parameters with the deviation's where it has them.
inline ValveSections machine_valve(const ValveSections& model, const ValveDeviation& d) {
  ValveSections out;  // no tables: the machine's characteristic is the line, gain and shape
  out.dead_zone = std::isnan(d.dead_zone) ? model.dead_zone : d.dead_zone;
  out.time_constant_s = std::isnan(d.time_constant_s) ? model.time_constant_s : d.time_constant_s;
  out.delay_s = std::isnan(d.delay_s) ? model.delay_s : d.delay_s;
  out.stroke_time_s = model.stroke_time_s;
  return out;
}

}  // namespace craneassist::dynamics
