#include "craneassist/config/quantity.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <numbers>

namespace craneassist::config {
namespace {

struct UnitDef {
  const char* name;
  Dimension dimension;
  double to_si;
};

constexpr double kPi = std::numbers::pi;

constexpr UnitDef kUnits[] = {
    {"m", Dimension::kLength, 1.0},
    {"mm", Dimension::kLength, 1e-3},
    {"cm", Dimension::kLength, 1e-2},
    {"rad", Dimension::kAngle, 1.0},
    {"deg", Dimension::kAngle, kPi / 180.0},
    {"kg", Dimension::kMass, 1.0},
    {"kg*m^2", Dimension::kInertia, 1.0},
    {"m/s", Dimension::kVelocity, 1.0},
    {"mm/s", Dimension::kVelocity, 1e-3},
    {"m/s^2", Dimension::kAcceleration, 1.0},
    {"m/s^3", Dimension::kJerk, 1.0},
    {"m^2", Dimension::kArea, 1.0},
    {"cm^2", Dimension::kArea, 1e-4},
    {"mm^2", Dimension::kArea, 1e-6},
    {"m^3/s", Dimension::kFlow, 1.0},
    {"L/min", Dimension::kFlow, 1e-3 / 60.0},
    {"Pa", Dimension::kPressure, 1.0},
    {"kPa", Dimension::kPressure, 1e3},
    {"MPa", Dimension::kPressure, 1e6},
    {"bar", Dimension::kPressure, 1e5},
    {"W", Dimension::kPower, 1.0},
    {"kW", Dimension::kPower, 1e3},
    {"s", Dimension::kTime, 1.0},
    {"ms", Dimension::kTime, 1e-3},
    {"Hz", Dimension::kFrequency, 1.0},
    {"1/s", Dimension::kInverseTime, 1.0},
    {"rad/s", Dimension::kAngularVelocity, 1.0},
    {"deg/s", Dimension::kAngularVelocity, kPi / 180.0},
    {"rpm", Dimension::kAngularVelocity, 2.0 * kPi / 60.0},
    {"m^3", Dimension::kVolume, 1.0},
    {"L", Dimension::kVolume, 1e-3},
    {"cm^3", Dimension::kVolume, 1e-6},
    {"1/m", Dimension::kInverseLength, 1.0},
    {"N", Dimension::kForce, 1.0},
    {"kN", Dimension::kForce, 1e3},
    {"N*s/m", Dimension::kDamping, 1.0},
    {"kN*s/m", Dimension::kDamping, 1e3},
    {"N*m*s/rad", Dimension::kRotaryDamping, 1.0},
    {"kN*m*s/rad", Dimension::kRotaryDamping, 1e3},
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::optional<double> parse_number(std::string_view token) {
  double value = 0.0;
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (first != last && *first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (ec != std::errc() || ptr != last || !std::isfinite(value)) return std::nullopt;
  return value;
}

// A number written against its unit ("21.5MPa", "-125deg"): the number and the unit, or
// nothing unless the token is a number followed by a letter ("1/s" is a unit, not 1 per s).
std::optional<std::pair<double, std::string_view>> split_number_unit(std::string_view token) {
  double value = 0.0;
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (first != last && *first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (ec != std::errc() || ptr == last || ptr == first || !std::isfinite(value) ||
      !std::isalpha(static_cast<unsigned char>(*ptr))) {
    return std::nullopt;
  }
  return std::pair{value, token.substr(static_cast<std::size_t>(ptr - token.data()))};
}

}  // namespace

const char* to_string(Dimension d) {
  switch (d) {
    case Dimension::kDimensionless:
      return "dimensionless";
    case Dimension::kLength:
      return "length";
    case Dimension::kAngle:
      return "angle";
    case Dimension::kMass:
      return "mass";
    case Dimension::kInertia:
      return "moment of inertia";
    case Dimension::kVelocity:
      return "velocity";
    case Dimension::kAcceleration:
      return "acceleration";
    case Dimension::kJerk:
      return "jerk";
    case Dimension::kArea:
      return "area";
    case Dimension::kFlow:
      return "volume flow";
    case Dimension::kPressure:
      return "pressure";
    case Dimension::kPower:
      return "power";
    case Dimension::kTime:
      return "time";
    case Dimension::kFrequency:
      return "frequency";
    case Dimension::kInverseTime:
      return "inverse time";
    case Dimension::kAngularVelocity:
      return "angular velocity";
    case Dimension::kVolume:
      return "volume";
    case Dimension::kInverseLength:
      return "inverse length";
    case Dimension::kForce:
      return "force";
    case Dimension::kDamping:
      return "damping (force per speed)";
    case Dimension::kRotaryDamping:
      return "rotary damping (torque per angular speed)";
  }
  return "?";
}

std::string accepted_units(Dimension dimension) {
  if (dimension == Dimension::kDimensionless) return "no unit";
  std::string out;
  for (const auto& u : kUnits) {
    if (u.dimension != dimension) continue;
    if (!out.empty()) out += ", ";
    out += u.name;
  }
  return out;
}

std::optional<Quantity> parse_quantity(std::string_view text, Dimension dimension,
                                       std::string& error) {
  Quantity q;
  std::string_view body = text;
  if (const auto comma = text.find(','); comma != std::string_view::npos) {
    body = text.substr(0, comma);
    const std::string_view source = trim(text.substr(comma + 1));
    if (source == "paper") {
      q.source = Source::kPaper;
    } else if (source == "assumed") {
      q.source = Source::kAssumed;
    } else if (source == "derived") {
      q.source = Source::kDerived;
    } else if (source == "standard") {
      q.source = Source::kStandard;
    } else if (source == "measured") {
      q.source = Source::kMeasured;
    } else {
      error = "unknown source '" + std::string(source) +
              "' (expected paper, assumed, derived, standard or measured)";
      return std::nullopt;
    }
  }
  // Tokens separated by blanks: numbers first, then at most one unit.
  body = trim(body);
  std::string_view unit;
  while (!body.empty()) {
    const auto end = body.find_first_of(" \t");
    const std::string_view token = body.substr(0, end);
    body = end == std::string_view::npos ? std::string_view{} : trim(body.substr(end));
    if (!unit.empty()) {
      error = "unexpected '" + std::string(token) + "' after the unit '" + std::string(unit) + "'";
      return std::nullopt;
    }
    if (const auto value = parse_number(token)) {
      q.si_values.push_back(*value);
    } else if (const auto joined = split_number_unit(token)) {
      q.si_values.push_back(joined->first);  // "0deg": the number, then its unit
      unit = joined->second;
    } else if (q.si_values.empty()) {
      error = "'" + std::string(token) + "' is not a finite number";
      return std::nullopt;
    } else {
      unit = token;
    }
  }
  if (q.si_values.empty()) {
    error = "no value given";
    return std::nullopt;
  }
  double scale = 1.0;
  if (unit.empty()) {
    if (dimension != Dimension::kDimensionless) {
      const std::string name = to_string(dimension);
      const bool vowel = name.find_first_of("aeiou") == 0;
      error = std::string("missing unit: ") + (vowel ? "an " : "a ") + name + " needs one of " +
              accepted_units(dimension);
      return std::nullopt;
    }
  } else {
    const UnitDef* found = nullptr;
    for (const auto& u : kUnits) {
      if (unit == u.name) found = &u;
    }
    if (found == nullptr || found->dimension != dimension) {
      error = "unit '" + std::string(unit) + "' is not a " + to_string(dimension) +
              " unit (expected " + accepted_units(dimension) + ")";
      return std::nullopt;
    }
    scale = found->to_si;
  }
  for (double& v : q.si_values) v *= scale;
  q.unit = std::string(unit);
  return q;
}

}  // namespace craneassist::config
