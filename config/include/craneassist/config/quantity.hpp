// Quantities as config files write them: "VALUE [VALUE ...] UNIT, SOURCE".
//
// "3.504 m, paper", "0 0 -9.81 m/s^2, standard", "0.53, paper" (no unit: dimensionless).
// Values are converted to SI; the unit must belong to the dimension the field expects.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace craneassist::config {

enum class Dimension {
  kDimensionless,
  kLength,
  kAngle,
  kMass,
  kInertia,
  kVelocity,
  kAcceleration,
  kJerk,
  kArea,
  kFlow,
  kPressure,
  kPower,
  kTime,
  kFrequency,
  kInverseTime,
  kAngularVelocity,
  kVolume,         // a displacement per revolution (hub motors)
  kInverseLength,  // a gain per metre (path-following gains)
  kForce,          // cylinder friction
  kDamping,        // viscous friction, force per speed
  kRotaryDamping,  // viscous friction of a joint, torque per angular speed
};

const char* to_string(Dimension dimension);

// Where a value comes from, as the config file states it.
enum class Source { kUnstated, kPaper, kAssumed, kDerived, kStandard, kMeasured };

struct Quantity {
  std::vector<double> si_values;  // converted to SI
  std::string unit;               // as written
  Source source = Source::kUnstated;
};

// Parses text; on failure returns std::nullopt and sets error to a one-line reason.
std::optional<Quantity> parse_quantity(std::string_view text, Dimension dimension,
                                       std::string& error);

// The accepted unit spellings of a dimension, for error messages and docs ("m, mm, cm").
std::string accepted_units(Dimension dimension);

}  // namespace craneassist::config
