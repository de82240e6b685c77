// Tool path following of the crane on wheels ("Flow-limited path-following control of a double
// Ackermann steered hydraulic mobile manipulator", section III and IV; docs/mobile.md): the tool
// follows a path in world coordinates, the platform the offset path beside it under the drive
// pump's flow bound (paths::BasePathFollower), and the arm holds the tool point relative to
// the measured platform through the crane's own controller (control::Controller: the
// redundancy resolution and the scaling of every tip command). With error scaling, the
// platform's speed is multiplied by delta(|e|) of the filtered tool error (eqs. 17-18).
//
// The machine is simulated: the ODE crane (sim_backend::SimBackend) on the kinematic base
// (sim_backend::MobileBaseSim). The run records one row per control cycle.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "craneassist/config/base_config.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/paths/base_path_follower.hpp"
#include "craneassist/paths/planar_path.hpp"

namespace craneassist::studies {

struct FollowOptions {
  bool error_scaling = true;  // case 2; false: case 1, the flow bound only
  // The tool height z(s) = tool_height + height_amplitude sin(2 pi height_cycles s) (the paper:
  // z = sin(8 pi s), 1 m and 4 cycles).
  double height_amplitude_m = 1.0;
  double height_cycles = 4.0;
  // The platform's start, relative to its reference pose at s = 0 in the path frame: along the
  // path, to the left, and the heading (the paper starts off the path without saying how far).
  double start_along_m = -0.5;
  double start_left_m = -1.0;
  double start_heading_rad = 0.15;
  double max_duration_s = 600.0;
  double settle_s = 2.0;  // run on this long after the platform has stopped at the end
};

struct FollowRow {
  double t = 0, s = 0, sdot = 0;
  double x = 0, y = 0, phi = 0;        // platform, measured
  double x_d = 0, y_d = 0, phi_d = 0;  // platform reference
  double e_x = 0, e_y = 0, e_phi = 0;
  double v_cmd = 0, omega_cmd = 0, v = 0, omega = 0, v_max = 0;
  double flow[4] = {0, 0, 0, 0};  // hub motors (of the lagged motion), m^3/s
  double flow_sum = 0, flow_max = 0;
  double steer[4] = {0, 0, 0, 0};
  double tool[3] = {0, 0, 0};    // measured tool, world
  double tool_d[3] = {0, 0, 0};  // desired tool, world
  double tool_error = 0, tool_error_filtered = 0, delta = 1;
  double q[4] = {0, 0, 0, 0};
  double arm_flow = 0;
  double arm_flow_max =
      0;  // what the crane's pump may deliver (less than its own with a shared pump)
  const char* limit = "";
};

struct FollowSummary {
  double completion_time_s = -1.0;  // s reached 1 (-1: not within max_duration_s)
  double peak_tool_error_m = 0.0;
  double rms_tool_error_m = 0.0;
  // The same after the start: from the first time the error came below 0.2 m (the initial
  // pose error corrected); -1 when it never did.
  double settled_at_s = -1.0;
  double peak_tool_error_settled_m = 0.0;
  double rms_tool_error_settled_m = 0.0;
  // The sum of hub-motor flows over Q_max, plus the crane's pump flow when it shares the pump
  // (BaseConfig::shared_with_crane); the motors alone.
  double peak_flow_ratio = 0.0;
  double peak_motor_flow_ratio = 0.0;
  double peak_commanded_flow_ratio = 0.0;
  double peak_slew_rate_rad_s = 0.0;
  double path_length_m = 0.0;
  double platform_path_length_m = 0.0;
  double final_platform_error_m = 0.0;
  long cycles = 0;
};

struct FollowResult {
  FollowSummary summary;
  std::vector<FollowRow> rows;
};

// Throws std::invalid_argument when the offset path cannot be followed (a cusp, or a turn
// tighter than the steering allows) or the crane cannot reach the tool's start.
FollowResult run_follow(const config::CraneConfig& crane, const config::BaseConfig& base,
                        const paths::CompositeBezierPath& path, const FollowOptions& options);

// The CSV log (docs/mobile.md#log): a comment block, a header, one line per row.
void write_follow_csv(std::ostream& out, const FollowResult& result, const std::string& comment);

}  // namespace craneassist::studies
