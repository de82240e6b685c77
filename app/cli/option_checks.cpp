#include "option_checks.hpp"

#include <cmath>
#include <sstream>
#include <string>

namespace craneassist::cli {
namespace {

// The option's text as a finite number, or false.
bool finite_number(const std::string& text, double& value) {
  return CLI::detail::lexical_cast(text, value) && std::isfinite(value);
}

}  // namespace

CLI::Validator FiniteRange(double lo, double hi) {
  std::ostringstream range;
  range << "[" << lo << ", " << hi << "]";
  const std::string text = range.str();
  return CLI::Validator(
      [lo, hi, text](std::string& input) {
        double value = 0.0;
        if (!finite_number(input, value) || value < lo || value > hi) {
          return "'" + input + "' is not a finite number in " + text;
        }
        return std::string();
      },
      "FLOAT in " + text, "FINITE_RANGE");
}

CLI::Validator FiniteNumber() {
  return CLI::Validator(
      [](std::string& input) {
        double value = 0.0;
        if (!finite_number(input, value)) return "'" + input + "' is not a finite number";
        return std::string();
      },
      "FLOAT", "FINITE");
}

}  // namespace craneassist::cli
