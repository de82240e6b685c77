// "As fast as the hydraulics allow", measured: the joint path of a tip path (a prescribed path
// file, or what a replay drove), its time-optimal traversal under the online scaler's limits, and
// the online scaler's own traversal (paths/time_optimal.hpp). `craneassist research bound` prints
// them.
#pragma once

#include <string>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/input/prescribed_path.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/paths/time_optimal.hpp"
#include "craneassist/studies/planning.hpp"

namespace craneassist::studies {

struct JointPathOptions {
  double ds_m = 0.01;  // path samples every ds
  StartExtension start = StartExtension::kShortest;
};

struct JointPath {
  std::vector<paths::PathSample> samples;  // uniform in s, the tip's arc length
  double start_extension_m = 0.0;
  // joint_path_for: the controller's time to drive the path, and whether it came to rest at the
  // end.
  double online_time_s = 0.0;
  bool online_arrived = false;
  std::vector<double> online_sdot;  // the controller's path speed at each sample
  // The drive's largest cylinder speed and acceleration over their limits (1: at the limit).
  double online_speed_share = 0.0, online_acceleration_share = 0.0;
  double online_deviation_m = 0.0;
  double online_power_share = 0.0;  // the reference's largest pump power over P_max  // the drive's
                                    // largest distance from the prescribed path
};

// The joint path the online controller (control::Controller, full scaling, the configured
// resolution) makes of a prescribed tip path when an operator drives it as fast as it goes: from
// the start point (inverse kinematics with the shortest feasible extension, or the middle of the
// feasible range, as paper 000 does), the stick towards the path half a second ahead at full
// request (easing off before bends so that the turning limit keeps the tip near the path),
// released so that the reference stops at the path's end; a machine that follows exactly, one
// valve delay late. The reference joint positions, resampled every ds in the
// tip's arc length, are the path; f', f'' from the samples. Throws std::runtime_error when the
// start is out of reach.
JointPath joint_path_for(const config::CraneConfig& cfg, const input::PrescribedPath& path,
                         const JointPathOptions& options);

// The joint path a replay drove on the simulated crane (the reference, resampled in its arc
// length), split where the reference came to rest (a reversal or a stop), with the operator's
// commanded speed as a cap at each sample. Each part starts and ends at rest; parts shorter than
// 5 cm are left out. online_time_s receives each part's duration in the run.
std::vector<JointPath> joint_paths_from_replay(const config::CraneConfig& cfg,
                                               const input::Replay& replay, double ds_m,
                                               std::vector<double>& online_time_s);

struct BoundFigures {
  double length_m = 0.0;
  paths::TimeOptimalResult bound;
};

// The bound of one joint path with the config's limits.
BoundFigures bound_figures(const config::CraneConfig& cfg, const JointPath& path);

}  // namespace craneassist::studies
