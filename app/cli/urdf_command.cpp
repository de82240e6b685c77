#include "urdf_command.hpp"

#include "crane_options.hpp"
#include "craneassist/dynamics/urdf.hpp"
#include "exit_codes.hpp"

namespace craneassist::cli {

CLI::App* add_urdf_command(CLI::App& cli, UrdfArgs& args) {
  auto* urdf = cli.add_subcommand(
      "urdf", "Write the crane as a robot description (URDF) for RViz, Foxglove and ROS tools");
  add_config_option(*urdf, args.config_file);
  add_payload_option(*urdf, args.payload_kg);
  urdf->add_option("-o,--output", args.output, "Write to this file (default: standard output)");
  urdf->add_option("--name", args.name, "The robot's name in the URDF")->capture_default_str();
  return urdf;
}

int run_urdf_command(const UrdfArgs& args) {
  config::CraneConfig cfg;
  try {
    cfg = load_crane(args.config_file);
    apply_crane_options(cfg, {.payload_kg = args.payload_kg});
  } catch (...) {
    return input_error_exit("config");
  }
  return write_output(dynamics::to_urdf(cfg.model, args.name), args.output,
                      std::to_string(cfg.model.dof()) + " joints" +
                          (cfg.model.grapple.hangs() ? ", the grapple on its two-axis link" : ""));
}

}  // namespace craneassist::cli
