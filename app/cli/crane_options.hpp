// The crane options of the commands that load a crane: --config, --payload, --initial and
// --resolution, with one help text each and one way to apply them.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <stdexcept>
#include <string>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/config/quantity.hpp"

namespace craneassist::cli {

// --config FILE: a crane config YAML; empty when not given (the embedded K70M reference crane).
CLI::Option* add_config_option(CLI::App& command, std::string& file);

// --payload KG: the payload mass in the grapple.
CLI::Option* add_payload_option(CLI::App& command, std::optional<double>& kg);

// --initial POSE: the simulated crane's start pose, e.g. "lift=0 deg, tilt=-125 deg".
CLI::Option* add_initial_option(CLI::App& command, std::string& pose);

// --resolution NAME: energy-optimal, pinv-joint, pinv-actuator, min-flow or min-ls-power (and,
// with allow_all, "all": each in turn); the value is empty when the option is not given (the
// config's redundancy.resolution then holds). `what` ends the help text, e.g. "for the run".
CLI::Option* add_resolution_option(CLI::App& command, std::string& value, const std::string& what,
                                   bool allow_all = false);

// --no-sway-damping: the run without the sway damping (docs/sway.md; the config's
// scaling.sway_damping off).
CLI::Option* add_sway_option(CLI::App& command, bool& off);

// The crane config `file`, or the embedded K70M reference crane when it is empty. Throws
// config::ConfigError naming the file, line and field.
config::CraneConfig load_crane(const std::string& file);

// What the crane options of a run set; empty or nullopt: the config's value holds.
struct CraneOptions {
  std::optional<double> payload_kg{};
  std::string initial{};
  std::string resolution{};
  bool initial_allowed = true;  // false on the can backend: it starts where the machine is
  bool no_sway_damping = false;
};

// Applies the options to `cfg`. A value the config cannot take throws CLI::ValidationError
// naming the option ("--initial: 'boom': no joint of that name").
void apply_crane_options(config::CraneConfig& cfg, const CraneOptions& options);

// A quantity given on the command line ("120 L/min"), in SI, or throws CLI::ValidationError
// naming the option. Its range is the config field's, checked when it is applied
// (apply_override).
double cli_quantity(const std::string& option, const std::string& text, config::Dimension dim);

// Applies a config field given on the command line with its config setter, set(), which checks
// it against the file's range (config::set_pump_max_flow, ...): the setter's
// std::invalid_argument becomes a CLI::ValidationError naming the option ("--pump-max-flow: must
// be positive and at most 60000 L/min (1 m^3/s)").
template <typename Set>
void apply_override(const char* option, Set&& set) {
  try {
    set();
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError(option, e.what());
  }
}

}  // namespace craneassist::cli
