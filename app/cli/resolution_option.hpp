// --resolution, the same choice and help on every command that drives the controller.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace craneassist::cli {

// --resolution NAME: energy-optimal, pinv-joint, pinv-actuator, min-flow or min-ls-power (and,
// with allow_all, "all": each in turn); the value is empty when the option is not given (the
// config's redundancy.resolution then holds). `what` ends the help text, e.g. "for the run".
CLI::Option* add_resolution_option(CLI::App& command, std::string& value, const std::string& what,
                                   bool allow_all = false);

}  // namespace craneassist::cli
