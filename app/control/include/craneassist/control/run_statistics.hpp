// What a run did, gathered cycle by cycle by an observer of the control loop: pump energy and
// peaks, tip speed and path, and for tip-velocity runs the direction errors, the active limits,
// stops and the operator feel (motion_quality.hpp). The replay summary and the live summary
// both come from it.
#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/control/controller.hpp"
#include "craneassist/control/motion_quality.hpp"
#include "craneassist/scaling/active_limit.hpp"

namespace craneassist::control {

struct RunStatisticsOptions {
  // Direction statistics count a cycle when the reference direction has been on the command
  // (within 0.5 deg, i.e. direction blending done) this long and the measured tip moves faster
  // than min_speed_m_s.
  double steady_after_s = 0.5;
  double min_speed_m_s = 0.05;
  // The second direction figure takes the tip's displacement over this window instead of the
  // measured velocity: on a real machine the velocity is differentiated from quantised encoder
  // frames and its noise is not the tip's motion (docs/can.md, "CAN versus sim"). At most
  // kMaxPositionWindow cycles; no longer than steady_after_s.
  double position_window_s = 0.1;
};

inline constexpr int kMaxPositionWindow = 64;

// The load over a run (docs/loads.md): the crane scale against the simulator's truth, and the
// rated capacity limiter.
struct LoadSummary {
  bool truth_known = false;  // a simulated machine (its load is known to the statistics only)
  double truth_kg = 0.0;     // the last cycle's
  double estimate_kg = 0.0;  // the last cycle's
  double sigma_kg = 0.0;
  bool converged = false;
  bool weighed = false;  // the scale had a measurement at least once
  // |estimate - truth| once the scale has converged and the load has not changed for
  // settled_after_s: at rest (tip slower than 0.01 m/s) and moving (faster than 0.05 m/s).
  double max_error_rest_kg = 0.0, max_error_moving_kg = 0.0;
  long rest_samples = 0, moving_samples = 0;
  double peak_moment_ratio = 0.0;
  long warning_cycles = 0;   // load moment at 90 % of the chart or more
  long overload_cycles = 0;  // the limiter tripped
  long refused_cycles = 0;   // a motion raising the load moment slowed to rest
  long relief_cycles = 0;    // a chamber at the load-holding valves' port relief (creeping)
  long truth_changes = 0;
};

// The hanging grapple's swing over the run (docs/sway.md; MachineState::swing_rad), degrees.
struct SwingSummary {
  bool measured = false;  // some cycle measured the swing
  double peak_deg = 0.0;
  // From 1 s after the stick last came back to rest (its command zero or no command) to the end:
  // the swing the last stop left (released false: the stick never came back to rest).
  bool released = false;
  double after_release_deg = 0.0;
  double end_deg = 0.0;  // the largest over the run's last second (what still swings)
  // The sway damping's tuning on the last cycle (ControllerOutput::sway_*; 0: not damping).
  double model_period_s = 0.0, period_s = 0.0;
  int measured_periods = 0;
};

// A replay's waits over a run (its wait rows; ReplayInput, docs/replay-format.md#waits).
struct WaitSummary {
  long waits = 0;      // wait rows reached
  long timed_out = 0;  // waits that ended at the timeout, not settled
  double total_s = 0.0, longest_s = 0.0;
  // The largest swing from 1 s after a wait began to its end (the swing the stop before it left,
  // which the wait is for; docs/sway.md), deg; NaN when nothing measured the swing.
  double residual_swing_deg = std::numeric_limits<double>::quiet_NaN();
};

// How the run's stops ended (docs/safety.md): a stop runs from its first cycle not running
// (kStopping) to its first cycle with every valve neutral (kStopped).
struct StopSummary {
  long stops = 0;  // stops that reached neutral valves
  // The last such stop (the end of run's, when the run ended by a stop):
  StopEnd end = StopEnd::kNone;
  double tip_speed_at_neutral_m_s = 0.0;  // measured on its kStopped cycle (NaN: no measurement)
  double time_s = 0.0;                    // from its first cycle to kStopped
  // Over every stop:
  double max_tip_speed_at_neutral_m_s = 0.0;  // the worst measured (valid measurements)
  long timeouts = 0;                          // ended by control.rest_timeout, still moving
  long unmeasured = 0;                        // ended without a valid measurement
  double peak_spool_step = 0.0;               // largest command change from one cycle to the next
  // Cycles with a section commanded fully open (|spool| >= 0.99) against the side it was
  // commanded when the stop began: a reverse kick.
  long full_reverse_cycles = 0;
  // Largest |load pressure| of any cylinder during the stops, and on the last running cycle
  // before the stop that reached it (the steady value the stop starts from).
  double peak_load_pressure_pa = 0.0;
  double steady_load_pressure_pa = 0.0;
};

struct RunSummary {
  long cycles = 0;
  double duration_s = 0.0;   // machine time
  double wall_time_s = 0.0;  // computer time
  double energy_j = 0.0;
  double peak_power_w = 0.0;
  double peak_flow_m3_s = 0.0;
  double peak_tip_speed_m_s = 0.0;
  double tip_path_m = 0.0;  // over valid measurements
  // Angle between commanded and measured tip velocity (steady cycles, see RunStatisticsOptions).
  double max_direction_error_deg = 0.0;
  double rms_direction_error_deg = 0.0;
  // The 95th percentile of the same cycles (within 0.01 deg below 10 deg, 1 deg above).
  double p95_direction_error_deg = 0.0;
  long direction_samples = 0;
  // The same cycles, the angle between the command and the tip's displacement over the last
  // position_window_s (what the tip did, free of the velocity estimate's noise).
  double max_position_direction_error_deg = 0.0;
  double rms_position_direction_error_deg = 0.0;
  double position_window_s = 0.0;
  // Angle between commanded and reference tip velocity (what the controller asked for).
  double max_reference_direction_error_deg = 0.0;
  long pump_saturated_cycles = 0;
  double peak_path_jerk = 0.0;    // max |sdddot| of the reference (full scaling)
  long stopped_cycles = 0;        // the controller stopping or stopped (kStopping, kStopped)
  long input_stop_cycles = 0;     // cycles without a command (a replay stop row, an input fault)
  long neutral_valve_cycles = 0;  // kStopped: at rest with every valve neutral
  std::array<long, scaling::kActiveLimitCount> limit_cycles{};  // indexed by scaling::ActiveLimit
  bool machine_fault = false;                                   // the loop stopped for it
  // The run reached its end moving and the loop stopped it (jerk-limited, then neutral valves)
  // in stop_cycles cycles; also set for a stop request (quit, fault) that ended the run.
  bool end_stop = false;
  long stop_cycles = 0;
  std::size_t log_rows_dropped = 0;
  MotionQualityResult feel;  // stall events and lateral speed (motion_quality.hpp)
  LoadSummary load;
  StopSummary stop;
  SwingSummary swing;
  double peak_spool_step = 0.0;  // largest command change from one cycle to the next, whole run
  // A replay's wait rows (ReplayInput) and its cycle time: the last row's time plus the time
  // waited (the time a scripted operator took; run_replay fills them).
  WaitSummary waits;
  double cycle_time_s = 0.0;
};

class RunStatistics final : public CycleObserver {
 public:
  RunStatistics(double period_s, const RunStatisticsOptions& options = {});
  bool reads_polytope() const noexcept override { return false; }
  void on_cycle(const CycleRecord& cycle) noexcept override;
  void on_finish(const CycleTime& last, const valves::MachineState& state) override;

  // The statistics with the loop's own figures (cycles, times, fault, dropped rows).
  RunSummary summary(const LoopSummary& loop) const;

 private:
  void add_load(double t, double tip_speed, const valves::MachineState& state,
                const ControllerOutput& out) noexcept;
  void add_stop(const CycleRecord& c, double tip_speed, double spool_step) noexcept;
  double period_s_;
  RunStatisticsOptions options_;
  RunSummary s_;
  MotionQuality quality_;
  double sum_sq_direction_ = 0.0;
  // Direction errors counted by bin (the p95): 0.01 deg bins up to 10 deg, then 1 deg bins.
  static constexpr int kFineBins = 1000, kCoarseBins = 171;
  std::array<long, kFineBins + kCoarseBins> direction_bins_{};
  Eigen::Vector3d last_cmd_ = Eigen::Vector3d::Zero();
  double cmd_since_s_ = 0.0;
  Eigen::Vector3d last_tip_ = Eigen::Vector3d::Zero();
  bool last_tip_valid_ = false;
  // The last window_ + 1 tips (a ring; valid flags beside), for the displacement.
  int window_ = 1;
  std::array<Eigen::Vector3d, kMaxPositionWindow + 1> tips_{};
  std::array<bool, kMaxPositionWindow + 1> tips_valid_{};
  long tip_count_ = 0;
  double sum_sq_position_direction_ = 0.0;
  long position_samples_ = 0;
  double truth_since_s_ = 0.0;  // the simulated load unchanged since
  // The last cycle's valve command (spool_count_ sections), and the stop in progress.
  std::array<double, dynamics::kMaxJoints> last_spool_{};
  std::array<double, dynamics::kMaxJoints> stop_start_spool_{};
  int spool_count_ = -1;
  bool in_stop_ = false, stop_counted_ = false;
  double stop_start_s_ = 0.0;
  double running_load_pressure_pa_ = 0.0;  // the last running cycle's
  double stop_steady_pa_ = 0.0, stop_peak_pa_ = 0.0;
  bool stick_moving_ = false;
  double release_s_ = 0.0;  // when the stick last came back to rest
  // The last cycles' swing (a ring, with their times), for the largest over the last second.
  static constexpr std::size_t kSwingRing = 1024;
  std::array<double, kSwingRing> swing_deg_{}, swing_t_{};
  std::size_t swing_count_ = 0;
};

// Angle between two vectors in degrees (0 when either is zero).
double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

}  // namespace craneassist::control
