// Checks of the command line's floating-point options. CLI11's CLI::Range and
// CLI::PositiveNumber let NaN through (every comparison with NaN is false, so `--settle nan`
// passed Range(0, 600) and `--can-feedback-timeout nan` reached the backend); these refuse NaN
// and the infinities, and CLI11 names the option in the error ("--settle: ...", exit 2).
#pragma once

#include <CLI/CLI.hpp>

namespace craneassist::cli {

// A finite number in [lo, hi] (both inclusive). Use it instead of CLI::Range and
// CLI::PositiveNumber on every floating-point option.
CLI::Validator FiniteRange(double lo, double hi);

// A finite number: for an option that overrides a config field, whose range the config's own
// check applies when the value is set (--payload, --can-feedback-timeout).
CLI::Validator FiniteNumber();

}  // namespace craneassist::cli
