// The mobile base's config (config/machines/mobile_base.yaml, docs/mobile.md): the
// double-Ackermann chassis, its hub motors and drive pump, where the crane stands on it, and the
// gains of the platform's path-following controller. Strict reader like the crane config's:
// unknown fields, missing fields, wrong units and out-of-range values are errors naming file,
// line and field (ConfigError).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "craneassist/dynamics/mobile_base.hpp"

namespace craneassist::config {

// The platform path-following controller's settings ("Flow-limited path-following control of a
// double Ackermann steered hydraulic mobile manipulator", eqs. 11-13, 17-18).
struct BaseFollowingConfig {
  double k1_1_m = 0.5;         // along-track error gain
  double k2 = 0.9;             // approach-angle gain of sigma, (0, 1]
  double k3_1_m = 1.0;         // heading gain (yaw rate per unit forward speed per rad)
  double epsilon_m = 0.5;      // sigma's smoothing
  double tool_offset_m = 4.5;  // tool path = platform path offset this far to the left
  double tool_height_m = 0.0;  // mean tool height above the ground plane
  double tool_error_ok_m = 0.05;
  double tool_error_filter_s = 0.05;
  double arm_position_gain_1_s = 2.0;
};

struct BaseConfig {
  dynamics::MobileBaseModel model;
  BaseFollowingConfig following;
  // The platform's planner counts the crane's measured pump flow against the drive pump's
  // (v_max from Q_max less the arm's flow).
  bool arm_shares_pump = false;
  // One pump of the drive's pump_max_flow feeds the hub motors and the crane: each simulation
  // step the crane's pump delivers at most what the motors leave of it (the drive first; the
  // paper's remark after eq. 15). false: the crane has its own pump (the paper's machine).
  bool shared_with_crane = false;
  std::string source_name;
};

// Parses YAML text; source_name names it in errors.
BaseConfig parse_base_config(std::string_view yaml_text, std::string_view source_name);
// Reads a file (at most 1 MiB); ConfigError naming the file when it cannot be read.
BaseConfig load_base_config(const std::filesystem::path& path);
// The shipped config/machines/mobile_base.yaml, embedded.
BaseConfig default_base_config();
// The file when given, else the embedded default.
BaseConfig load_base_or_default(const std::string& path);

}  // namespace craneassist::config
