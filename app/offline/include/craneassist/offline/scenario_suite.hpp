// A scenario suite: replays, start poses, payloads and the targets each run must meet, read from
// a YAML manifest (format craneassist-suite/1, docs/suite-format.md; the operator-feel suite is
// examples/replays/suite.yaml). Each run goes through the same loop as `craneassist replay` on the
// simulated crane and is checked against its targets (stall events, lateral speed, peak pump
// power, direction error; app/motion_quality.hpp).
#pragma once

#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/replay_runner.hpp"

namespace craneassist::offline {

struct SuiteTargets {
  std::optional<int> stall_events;                // at most this many
  std::optional<double> lateral_speed_m_s;        // one-line replays only, over 50 ms
  std::optional<double> peak_power_share;         // measured pump power over P_max
  std::optional<double> direction_error_rad;      // commanded vs measured, steady cycles: the max
  std::optional<double> direction_error_p95_rad;  // the same cycles' 95th percentile
  std::optional<int> stop_timeouts;  // stops that reached neutral still moving (rest_timeout)
  // Replays with wait rows (docs/replay-format.md#waits): the residual swing (the largest from
  // 1 s into a wait), the cycle time (the last row's time plus the waits), waits that timed out.
  std::optional<double> residual_swing_rad;
  std::optional<double> cycle_time_s;
  std::optional<int> timed_out_waits;
  std::optional<int> overload_cycles;  // the rated capacity limiter tripped (docs/loads.md)
};

struct SuiteRun {
  std::string replay_text;       // as the manifest writes it
  std::filesystem::path replay;  // resolved against the manifest's folder
  std::string pose;              // "default" or a name from poses:
  std::string pose_text;         // NAME=VALUE UNIT, ...; empty for default
  double payload_kg = 0.0;
  bool payload_known = false;  // tell the controller (else the crane scale weighs the load)
  // The run's scaling and sway damping (a baseline: flow, false); unset: full, the config's.
  control::ScalingMode scaling = control::ScalingMode::kFull;
  std::optional<bool> sway_damping;
  double wait_swing_rad = 2.0 * M_PI / 180.0;  // how its wait rows wait
  SuiteTargets targets;
  int line = 0;       // of the run in the manifest
  int pose_line = 0;  // of its pose
  // "replay @pose", with "(scaling flow, no sway damping)" for a run other than the default.
  std::string name() const;
  // The same run but for its scaling and sway damping (a baseline and the run it is for).
  bool same_motion(const SuiteRun& other) const {
    return replay == other.replay && pose == other.pose && payload_kg == other.payload_kg &&
           payload_known == other.payload_known && wait_swing_rad == other.wait_swing_rad;
  }
};

struct Suite {
  std::string source;
  std::vector<SuiteRun> runs;  // one per replay and pose
};

// Read and validate a manifest; replay files must exist. Throw config::ConfigError naming the
// file, line and field.
Suite load_suite(const std::filesystem::path& path);
Suite parse_suite(std::string_view yaml_text, std::string_view source_name,
                  const std::filesystem::path& base_dir);

// Checks every pose against the crane that runs the suite (joint names, ranges); throws
// config::ConfigError naming the manifest, the pose's line and field.
void check_suite(const Suite& suite, const config::CraneConfig& cfg);

struct SuiteOutcome {
  control::RunSummary summary;
  double p_max_w = 0.0;
  std::vector<std::string> missed;  // the targets the run missed, each with its figure
  bool ok() const { return missed.empty(); }
};

// A machine the suite runs on besides the config's own (`craneassist suite --variants FILE`,
// format craneassist-variants/1, docs/suite-format.md#machine-variants): the simulated machine's
// valves, joint sensors and feedback where they differ from the controller's model, and targets
// that replace the suite's for its runs.
struct SuiteVariant {
  std::string name;
  int line = 0;
  dynamics::ValveDeviations valves{};
  dynamics::JointSensing joints{};
  SuiteTargets targets;  // over each run's own
  // cfg with this machine (cfg.simulation.valves and joints replaced).
  config::CraneConfig apply(const config::CraneConfig& cfg) const;
};

// Read and validate a variants file against the crane that runs them (joint names); throw
// config::ConfigError naming the file, line and field.
std::vector<SuiteVariant> load_variants(const std::filesystem::path& path,
                                        const config::CraneConfig& cfg);
std::vector<SuiteVariant> parse_variants(std::string_view yaml_text, std::string_view source_name,
                                         const config::CraneConfig& cfg);

// Runs one entry on the simulated crane described by base (its payload and start pose applied)
// with the given resolution (a name config::set_resolution takes; empty: base's). log_file empty:
// no log. Throws what loading the replay or the pose throws (the manifest was checked, so only
// for files changed since).
SuiteOutcome run_suite_run(const config::CraneConfig& base, const SuiteRun& run,
                           const std::string& resolution, const std::filesystem::path& log_file);
// The same with the variant's targets over the run's.
SuiteOutcome run_suite_run(const config::CraneConfig& base, const SuiteRun& run,
                           const SuiteTargets& over, const std::string& resolution,
                           const std::filesystem::path& log_file);

}  // namespace craneassist::offline
