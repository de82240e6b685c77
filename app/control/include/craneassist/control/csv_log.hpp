// The per-cycle CSV log (columns in docs/log-format.md).
//
// The control loop hands each row to a fixed-size single-producer/single-consumer ring and
// returns at once: no lock, no allocation, no I/O on the loop thread. A writer thread formats
// and writes the rows. If the writer falls behind and the ring fills, rows are dropped and
// counted (never the loop blocked); close() reports the count.
#pragma once

#include <array>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "craneassist/control/spsc_ring.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::control {

struct LogRow {
  static constexpr int kMaxJoints = dynamics::kMaxJoints;
  double t = 0.0;
  std::array<double, 3> cmd{}, ref_v{}, tip{}, tip_v{};
  std::array<double, kMaxJoints> q{}, q_ref{}, spool{}, load_pressure{};
  double pump_flow_m3s = 0.0, pump_pressure_pa = 0.0, pump_power_w = 0.0, energy_j = 0.0;
  double scale = 0.0, flow_demand_m3s = 0.0;
  double s = 0.0, sdot = 0.0, sddot = 0.0, sdddot = 0.0, sddot_min = 0.0, sddot_max = 0.0;
  double tip_error_m = 0.0;
  double ref_power_w = 0.0;  // pump power the model predicts for the reference
  // The flow manipulability polytope (ControllerOutput).
  double avail_speed_m_s = 0.0, avail_speed_resolved_m_s = 0.0, polytope_volume_m3s3 = 0.0;
  // The load (docs/loads.md): the simulator's truth (NaN on a machine), the crane scale's
  // estimate, the load moment against the chart (ControllerOutput::load).
  double load_kg = std::numeric_limits<double>::quiet_NaN();
  double payload_estimate_kg = 0.0, load_moment_ratio = 0.0;
  // The hanging grapple's swing (docs/sway.md; MachineState), rad (the CSV writes degrees): from
  // the vertical, towards the reach and across it. NaN where nothing measures it.
  double swing_rad = std::numeric_limits<double>::quiet_NaN();
  double swing_radial_rad = std::numeric_limits<double>::quiet_NaN();
  double swing_tangential_rad = std::numeric_limits<double>::quiet_NaN();
  // Telemetry only (not in the CSV): the angles and rates of the URDF's hanger joints that draw
  // the grapple where the swing has it (dynamics::hanger_joint_angles; straight down where
  // nothing measures the swing), rad and rad/s. Zero without a hanging grapple.
  std::array<double, 2> hanger_rad{}, hanger_rate_rad_s{};
  // Live and telemetry only (not in the CSV): the chart's rated load at the reach, the reach,
  // and the scale's and limiter's state.
  double rated_load_kg = 0.0, load_reach_m = 0.0;
  // The pump's limits (the model's; live and telemetry only): what pump_flow_m3s and
  // pump_power_w are plotted against.
  double flow_limit_m3s = 0.0, power_limit_w = 0.0;
  bool payload_converged = false, load_warning = false, load_overload = false;
  const char* active_limit = "";  // static strings only (to_string of the enums)
  const char* pump_limit = "";
  // Live-loop fields (the live loop and telemetry fill them; the CSV writer does not write them):
  // joint rates, cylinder positions and velocities, loop and input status. Static strings only.
  std::array<double, kMaxJoints> qdot{}, cylinder_pos{}, cylinder_vel{};
  // The polytope's dimension and, when flat (a planar arm), its area (ControllerOutput).
  int polytope_dim = 0;
  double polytope_area_m2s2 = 0.0;
  const char* status = "";       // "running", "stopping", "stopped"
  const char* stop_reason = "";  // why the loop stops or holds ("" while running)
  const char* input_source = "";
  bool deadman = false;
  // Cycle timing (the control loop fills them, cycle_timing.hpp): the worst start latency of the
  // run so far (0 when not paced), the previous cycle's compute time, the overruns so far.
  double loop_latency_max_s = 0.0, loop_compute_s = 0.0;
  long loop_overruns = 0;
  // The wheeled base under the crane (sim --drive; MachineState::base) and the drive command
  // written with the spools (live and telemetry only, like the fields above). Zero on a fixed
  // base (base_present false).
  bool base_present = false;
  bool base_shared_pump = false;            // the crane's pump flow counts against the same Q_max
  std::array<double, 3> base_pose{};        // x, y (m), heading (rad), world
  std::array<double, 2> base_velocity{};    // forward speed (m/s), yaw rate (rad/s)
  std::array<double, 2> base_command{};     // the drive command, the same units
  std::array<double, 4> base_motor_flow{};  // hub motors fl, fr, rl, rr, m^3/s
  double base_flow_sum_m3s = 0.0, base_flow_max_m3s = 0.0;

  // The pump columns from a measurement.
  void set_pump(const valves::PumpMeasurement& pump) {
    pump_flow_m3s = pump.flow_m3_s;
    pump_pressure_pa = pump.pressure_pa;
    pump_power_w = pump.power_w;
    energy_j = pump.energy_j;
    pump_limit = valves::to_string(pump.limit);
  }
};

class CsvLog {
 public:
  // Opens the file and writes the header; throws std::runtime_error naming the file on failure.
  // With `base` (a crane on the wheeled base, sim --drive) the base's columns follow.
  CsvLog(const std::filesystem::path& path, int dof, std::size_t capacity_rows = 1 << 14,
         bool base = false);
  ~CsvLog();
  CsvLog(const CsvLog&) = delete;
  CsvLog& operator=(const CsvLog&) = delete;

  // Real-time safe: copies the row into the ring; returns false (and counts) when full.
  bool push(const LogRow& row) noexcept;

  // Drains the ring, stops the writer and closes the file. Returns the number of dropped rows.
  std::size_t close();

  std::size_t rows_written() const { return written_.load(); }
  const std::filesystem::path& path() const { return path_; }

  static std::string header(int dof, bool base = false);

 private:
  void writer_loop();
  void write_row(const LogRow& row);

  std::filesystem::path path_;
  int dof_;
  bool base_ = false;
  std::FILE* file_ = nullptr;
  SpscRing<LogRow> ring_;
  std::atomic<bool> stop_{false};
  std::atomic<std::size_t> dropped_{0};
  std::atomic<std::size_t> written_{0};
  std::thread writer_;
};

}  // namespace craneassist::control
