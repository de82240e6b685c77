// Valve calibration (`craneassist calibrate`, docs/valves.md): a command sweep on one section at
// a time, the steady cylinder velocity at every level in both directions, and the monotone table
// (hydraulics.valves.tables) fitted to it. One sweep task (calibration.cpp) drives any
// valves::MachineInterface: on the simulator each level starts on a fresh crane placed at
// mid-stroke; on a machine (the CAN backend, or the simulator standing in for one) the task moves
// the section back to mid-stroke itself before every level. The sweep is offline and allocates
// freely before and after its control loop; the loop's cycles allocate nothing.
#pragma once

#include <atomic>
#include <iosfwd>
#include <span>
#include <string>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::offline {

// How a sweep on a machine brings the section back to mid-stroke before each level, and how it
// handles the spools there: a P loop on the cylinder position through the config's valve model
// (its table, or the straight line through dead_zone and max_speed), with a speed cap and a spool
// limit, stopped within a tolerance; then neutral until the cylinder is at rest. A spool of a
// machine sweep closes (towards neutral, or through it) at most at spool_rate_1_s, so neither a
// level's end nor a stop takes a moving section from flow to neutral in one cycle; it opens as
// commanded (a level starts with a step, as on the simulator).
struct MidStrokeMove {
  double gain_1_s = 2.0;              // cylinder velocity reference per metre of position error
  double speed_fraction = 0.5;        // speed cap: this share of the cylinder's max_speed
  double spool_max = 0.8;             // |spool| limit while moving
  double tolerance = 0.01;            // share of the stroke: close enough to mid-stroke
  double rest_speed_fraction = 0.03;  // at rest below this share of max_speed
  double rest_s = 0.3;                // within the tolerance, neutral and at rest this long
  double timeout_s = 30.0;            // a move that takes longer fails the sweep
  double spool_rate_1_s = 2.0;        // closing rate limit (full to neutral in 0.5 s)
};

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
  // On a machine the window is judged with this tolerance instead: at a steady speed the
  // halves of a window measured over CAN differ by up to 3 % (the encoders' resolution, the
  // bus's and the machine's timing; tests/offline/test_calibration_can.cpp), and a level found not
  // settled is measured again, from mid-stroke, up to machine_retries times.
  double machine_settled_tolerance = 0.03;
  int machine_retries = 2;
  // Share of the stroke kept clear of either end stop: a level whose measurement window would
  // come closer is recorded as invalid (not fitted).
  double end_margin = 0.05;
  // Below this share of the section's top measured speed a velocity counts as zero (dead band).
  double zero_fraction = 1e-3;
  MidStrokeMove move;  // on a machine only
};

// "" when `levels` can be swept (at least one, each in (0, 1], strictly ascending), else why not.
std::string check_levels(const std::vector<double>& levels);

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

// A section's spool dynamics identified from the sweep's step responses (every level starts
// with a step from neutral): when the cylinder starts to move (its velocity passing 0.3 % of the
// top speed) depends on the level c through the spool's travel across the dead band,
// t_on = delay + time_constant * ln(c / (c - x_on)), x_on the command at which the fitted table
// passes that speed; a line fitted through the levels' onsets (those moving at 10 % of the top
// speed or more) gives both. The onset is set by the spool alone: the mass's acceleration, which
// shapes the rise after it, does not enter.
struct ValveDynamics {
  bool identified = false;
  double delay_s = 0.0;
  double time_constant_s = 0.0;
  double residual_s = 0.0;  // rms misfit of the onsets
  int levels = 0;           // onsets fitted
  std::string why_not;      // when not identified
};

struct SectionCalibration {
  int section = 0;
  ValveDynamics dynamics;
  std::vector<SweepPoint> points;                          // ascending command, (0, 0) included
  dynamics::ValveTable table;                              // monotone fit
  double dead_band_retract = 0.0, dead_band_extend = 0.0;  // signed edges of the fitted table
  double max_retract_m_s = 0.0, max_extend_m_s = 0.0;      // at the extreme levels
};

// Sweeps section `section` of the crane in the simulator, starting every level on a fresh
// simulated crane with that joint at mid-stroke and the others at the config's initial position;
// appends to `log` when given. Throws std::invalid_argument for a section the crane lacks.
SectionCalibration calibrate_section(const config::CraneConfig& config, int section,
                                     const CalibrationOptions& options,
                                     std::vector<SweepLogRow>* log = nullptr);

// How a sweep on a machine ended.
enum class SweepEnd {
  kComplete,
  kStopRequested,  // the stop flag (SIGINT): spools ramped to neutral
  kMachineFault,   // the machine latched a fault (it blocked its valves itself)
  kNotPositioned,  // the section did not reach mid-stroke within move.timeout_s
};
const char* to_string(SweepEnd end);

struct MachineSweep {
  SectionCalibration section;  // fitted only when complete
  SweepEnd end = SweepEnd::kComplete;
  std::string reason;        // why it ended early; "" when complete
  double duration_s = 0.0;   // machine time of the sweep
  double wall_time_s = 0.0;  // computer time (the same on a real-time machine)
};

// Sweeps section `section` on an active machine in one control loop, paced at real time when
// the machine is (MachineInterface::real_time): before every level the section is moved to
// mid-stroke (options.move) with every other section neutral; a level ends early, as invalid,
// when the cylinder would pass the end margin before it can stop. The loop stops when `stop`
// becomes true or the machine faults, the spools ramping to neutral; at the end every spool is
// neutral. The caller deactivates the machine. Appends the levels' cycles to `log` when given.
// Throws std::invalid_argument for a section the crane lacks.
MachineSweep calibrate_section_on_machine(const config::CraneConfig& config,
                                          valves::MachineInterface& machine, int section,
                                          const CalibrationOptions& options,
                                          const std::atomic<bool>* stop = nullptr,
                                          std::vector<SweepLogRow>* log = nullptr);

// The monotone table through sweep points (ascending command): pool-adjacent-violators isotonic
// regression of velocity on command, velocities below zero_speed_m_s set to 0, the dead-band edge
// on each side placed where the first moving segment extrapolates to zero velocity (kept between
// the last still and the first moving level), pooled runs merged into one point. Passes
// dynamics::check_valve_table when the points move both ways.
dynamics::ValveTable fit_valve_table(const std::vector<SweepPoint>& points, double zero_speed_m_s);

// Identifies section `section`'s spool delay and time constant from its rows of a sweep log
// (each level's rows from its step, t since the level started) and its fitted table. Not
// identified, with the reason, when the table is unusable, fewer than 3 levels start moving
// clearly, the fit gives no physical spool, or its rms misfit exceeds max_residual times the
// time constant (and 5 ms).
ValveDynamics identify_valve_dynamics(const dynamics::ValveTable& table,
                                      std::span<const SweepLogRow> rows, int section,
                                      double max_residual = 0.2);

// The identified dynamics as the controller is given them (the table's time_constant and delay):
// the delay as measured, the time constant kLeadTimeConstantShare of the measured one. The
// dead-band lead overshoots into flow on a spool faster than the one it plans for, and a few
// per cent too slow a plan already makes it hunt (docs/valves.md#the-machine-it-meets), so the
// plan errs on the fast side by more than the identification's error (3 % on the simulator).
inline constexpr double kLeadTimeConstantShare = 0.95;
void apply_dynamics(const ValveDynamics& found, dynamics::ValveTable& table);

// The YAML block to paste under hydraulics.valves (indented for it): each section's table and,
// where identified, its spool time constant and delay (apply_dynamics).
std::string valve_tables_yaml(const dynamics::CraneModel& model,
                              const std::vector<SectionCalibration>& sections,
                              const std::string& comment);

// The sweep log as CSV: section,joint,command,t,cylinder_position,cylinder_velocity,measuring.
void write_sweep_log(std::ostream& out, const dynamics::CraneModel& model,
                     const std::vector<SweepLogRow>& rows);

}  // namespace craneassist::offline
