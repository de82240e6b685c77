// Valve calibration (`craneassist calibrate`, docs/valves.md): a command sweep on one section at
// a time, the steady cylinder velocity at every level in both directions, and the monotone table
// (hydraulics.valves.tables) fitted to it. Runs on the simulator; offline, so it allocates freely.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/model.hpp"

namespace craneassist::offline {

struct CalibrationOptions {
  // Command magnitudes stepped through, each in both directions (ascending, in (0, 1]).
  std::vector<double> levels = {0.1, 0.2,  0.3, 0.4, 0.45, 0.5,  0.55,
                                0.6, 0.65, 0.7, 0.8, 0.9,  0.95, 1.0};
  // Hold before measuring: transport delay, spool lag and the acceleration of the mass (the
  // K70M's slew needs about 0.8 s to reach full speed).
  double settle_s = 1.2;
  double measure_s = 0.3;  // the steady velocity is the mean over this window
  // A level whose mean velocities over the two halves of the window differ by more than this
  // share is recorded as not settled (invalid, not fitted).
  double settled_tolerance = 0.01;
  // Share of the stroke kept clear of either end stop: a level whose measurement window would
  // come closer is recorded as invalid (not fitted).
  double end_margin = 0.05;
  // Below this share of the section's top measured speed a velocity counts as zero (dead band).
  double zero_fraction = 1e-3;
};

// One level held in one direction.
struct SweepPoint {
  double command = 0.0;       // normalised spool command, signed
  double velocity_m_s = 0.0;  // steady cylinder velocity
  bool valid = false;         // settled, and clear of the end stops during the window
};

// One row of the sweep log (every control cycle of every level).
struct SweepLogRow {
  int section = 0;
  double command = 0.0;
  double t_s = 0.0;  // since the level started
  double cylinder_m = 0.0;
  double cylinder_velocity_m_s = 0.0;
  bool measuring = false;
};

struct SectionCalibration {
  int section = 0;
  std::vector<SweepPoint> points;                          // ascending command, (0, 0) included
  dynamics::ValveTable table;                              // monotone fit
  double dead_band_retract = 0.0, dead_band_extend = 0.0;  // signed edges of the fitted table
  double max_retract_m_s = 0.0, max_extend_m_s = 0.0;      // at the extreme levels
};

// Sweeps section `section` of the crane in the simulator, starting every level at mid-stroke with
// the other joints at the config's initial position; appends to `log` when given.
SectionCalibration calibrate_section(const config::CraneConfig& config, int section,
                                     const CalibrationOptions& options,
                                     std::vector<SweepLogRow>* log = nullptr);

// The monotone table through sweep points (ascending command): pool-adjacent-violators isotonic
// regression of velocity on command, velocities below zero_speed_m_s set to 0, the dead-band edge
// on each side placed where the first moving segment extrapolates to zero velocity (kept between
// the last still and the first moving level), pooled runs merged into one point. Passes
// dynamics::check_valve_table when the points move both ways.
dynamics::ValveTable fit_valve_table(const std::vector<SweepPoint>& points, double zero_speed_m_s);

// The YAML block to paste under hydraulics.valves (indented for it).
std::string valve_tables_yaml(const dynamics::CraneModel& model,
                              const std::vector<SectionCalibration>& sections,
                              const std::string& comment);

// The sweep log as CSV: section,joint,command,t,cylinder_position,cylinder_velocity,measuring.
void write_sweep_log(std::ostream& out, const dynamics::CraneModel& model,
                     const std::vector<SweepLogRow>& rows);

}  // namespace craneassist::offline
