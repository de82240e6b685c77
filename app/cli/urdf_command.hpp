// `craneassist urdf`: the crane as a robot description (URDF) for RViz, Foxglove and other ROS
// tools (dynamics/urdf.hpp, docs/ros.md).
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace craneassist::cli {

struct UrdfArgs {
  std::string config_file;  // empty: the embedded reference crane
  std::optional<double> payload_kg;
  std::string output;  // empty: standard output
  std::string name = "craneassist_crane";
};

CLI::App* add_urdf_command(CLI::App& cli, UrdfArgs& args);
int run_urdf_command(const UrdfArgs& args);

}  // namespace craneassist::cli
