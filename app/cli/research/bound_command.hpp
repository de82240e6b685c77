// `craneassist research bound FILE`: the time-optimal traversal of a tip path (a path file,
// docs/path-format.md) or of what a replay drove, under the online scaler's limits, against the
// online scaler's own time (app/path_bound.hpp, docs/scaling.md, "As fast as the hydraulics
// allow").
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace craneassist::cli {

struct BoundArgs {
  std::string file;
  std::string config_file;  // empty: the embedded reference crane
  std::optional<double> payload_kg;
  std::string resolution;  // empty: the config's
  std::string start = "shortest";
  double ds_m = 0.01;
  std::string profile_file;  // empty: none
  bool no_sway_damping = false;
};

CLI::App* add_bound_command(CLI::App& cli, BoundArgs& args);
int run_bound_command(const BoundArgs& args);

}  // namespace craneassist::cli
