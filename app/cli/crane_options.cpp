#include "crane_options.hpp"

#include <stdexcept>
#include <vector>

#include "option_checks.hpp"

namespace craneassist::cli {

CLI::Option* add_config_option(CLI::App& command, std::string& file) {
  return command
      .add_option("--config", file,
                  "Crane config YAML (default: the embedded K70M reference crane)")
      ->check(CLI::ExistingFile);
}

CLI::Option* add_payload_option(CLI::App& command, std::optional<double>& kg) {
  // The range is payload.mass's, checked when the value is applied (config::set_payload_mass).
  return command.add_option("--payload", kg, "Payload mass in the grapple, kg, 0 to 100000")
      ->check(FiniteNumber());
}

CLI::Option* add_initial_option(CLI::App& command, std::string& pose) {
  return command.add_option("--initial", pose,
                            "Start pose of the simulated crane, e.g. \"lift=0 deg, tilt=-125 deg, "
                            "extension=0.2 m\" (joints left out keep the config's "
                            "simulation.initial)");
}

CLI::Option* add_resolution_option(CLI::App& command, std::string& value, const std::string& what,
                                   bool allow_all) {
  std::vector<std::string> names = config::resolution_names();
  std::string help =
      "Redundancy resolution " + what +
      ": energy-optimal (min-ls-power with a load-sensing pump, min-flow with a constant-pressure "
      "one), pinv-joint, pinv-actuator, min-flow or min-ls-power";
  if (allow_all) {
    names.insert(names.begin(), "all");
    help += ", or all (each in turn)";
  }
  help += "; default: the config's redundancy.resolution";
  return command.add_option("--resolution", value, help)->check(CLI::IsMember(names));
}

double cli_quantity(const std::string& option, const std::string& text, config::Dimension dim) {
  std::string error;
  const auto q = config::parse_quantity(text, dim, error);
  if (!q || q->si_values.size() != 1) {
    throw CLI::ValidationError(option, error.empty() ? "expected one value" : error);
  }
  return q->si_values[0];
}

config::CraneConfig load_crane(const std::string& file) {
  return file.empty() ? config::default_crane_config() : config::load_crane_config(file);
}

CLI::Option* add_sway_option(CLI::App& command, bool& off) {
  return command.add_flag("--no-sway-damping", off,
                          "Leave the grapple's swing undamped (the config's scaling.sway_damping "
                          "off; docs/sway.md)");
}

void apply_crane_options(config::CraneConfig& cfg, const CraneOptions& options) {
  if (options.no_sway_damping) cfg.scaling.sway_damping = false;
  if (options.payload_kg) {
    apply_override("--payload", [&] { config::set_payload_mass(cfg.model, *options.payload_kg); });
  }
  if (!options.initial.empty()) {
    if (!options.initial_allowed) {
      throw CLI::ValidationError("--initial",
                                 "the can backend starts where the machine is (use --backend sim)");
    }
    try {
      cfg.simulation.q_initial =
          config::parse_joint_pose(cfg.model, options.initial, cfg.simulation.q_initial);
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--initial", e.what());
    }
  }
  if (!options.resolution.empty()) {
    try {
      config::set_resolution(cfg, options.resolution);
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--resolution", e.what());
    }
  }
}

}  // namespace craneassist::cli
