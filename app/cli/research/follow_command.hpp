// `craneassist research follow PATH`: the crane on wheels follows a tool path
// (offline/mobile_follow.hpp, docs/mobile.md): the platform on the offset path under the drive
// pump's flow bound, the arm holding the tool, and with error scaling (the default) the platform
// slowed by the tool error. Prints the figures (tool error, completion time, peak flow ratio) and
// writes a CSV log.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace craneassist::cli {

struct FollowArgs {
  std::string path_file;
  std::string config_file;  // crane; empty: the embedded K70M
  std::string base_file;    // base; empty: the embedded config/machines/mobile_base.yaml
  bool no_error_scaling = false;
  std::string pump;  // "shared", "separate"; empty: the base config's drive.shared_with_crane
  std::string log = "follow.csv";
  bool no_log = false;
  std::optional<double> height_amplitude_m;
  std::optional<double> height_cycles;
  std::optional<double> max_duration_s;
};

CLI::App* add_follow_command(CLI::App& cli, FollowArgs& args);
int run_follow_command(const FollowArgs& args);

}  // namespace craneassist::cli
