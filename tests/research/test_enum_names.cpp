// Enum values by name (dynamics/enum_names.hpp): every enum that the config files or the command
// line spell has its names in one to_string() and its values in one array beside it; parse gives
// back each value from its name, and nothing else.
#include <gtest/gtest.h>

#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/control/controller.hpp"
#include "craneassist/dynamics/enum_names.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/resolutions.hpp"
#include "craneassist/planner/stage_model.hpp"
#include "craneassist/scaling/path_constraints.hpp"
#include "craneassist/studies/planning.hpp"

namespace craneassist {
namespace {

// Every value parses back from its name; the names are distinct and as expected; near misses
// (other case, spaces, a prefix, empty) are rejected.
template <typename Enum, std::size_t N, typename Parse>
void expect_round_trip(const std::array<Enum, N>& values, Parse parse,
                       const std::vector<std::string>& expected_names) {
  EXPECT_EQ(names_of(values), expected_names);
  std::set<std::string> seen;
  for (const Enum value : values) {
    const std::string name = to_string(value);
    SCOPED_TRACE(name);
    EXPECT_TRUE(seen.insert(name).second) << "duplicate name";
    const std::optional<Enum> parsed = parse(name);
    ASSERT_TRUE(parsed.has_value());
    EXPECT_EQ(*parsed, value);
    std::string upper = name;
    for (char& c : upper) c = static_cast<char>(c >= 'a' && c <= 'z' ? c - 'a' + 'A' : c);
    EXPECT_FALSE(parse(upper).has_value());
    EXPECT_FALSE(parse(" " + name).has_value());
    EXPECT_FALSE(parse(name + " ").has_value());
    EXPECT_FALSE(parse(name.substr(0, name.size() - 1)).has_value());
  }
  EXPECT_FALSE(parse("").has_value());
  EXPECT_FALSE(parse("?").has_value());
}

TEST(EnumNames, PumpMode) {
  expect_round_trip(dynamics::kPumpModes, dynamics::parse_pump_mode,
                    {"load-sensing", "constant-pressure"});
  // The command line's short forms are its own, not config names.
  EXPECT_FALSE(dynamics::parse_pump_mode("ls").has_value());
  EXPECT_FALSE(dynamics::parse_pump_mode("cp").has_value());
}

TEST(EnumNames, PowerBound) {
  expect_round_trip(dynamics::kPowerBounds, dynamics::parse_power_bound,
                    {"load_sensing", "actuator_sum", "none"});
  // One type, seen from the path scaling and from the config.
  const scaling::PowerBound from_scaling = scaling::PowerBound::kActuatorPowerSum;
  config::ScalingSettings settings;
  settings.power_bound = from_scaling;
  EXPECT_EQ(settings.power_bound, dynamics::PowerBound::kActuatorPowerSum);
  EXPECT_EQ(config::ScalingSettings{}.power_bound, dynamics::PowerBound::kLoadSensing);
}

TEST(EnumNames, Resolution) {
  expect_round_trip(dynamics::kResolutions, dynamics::parse_resolution,
                    {"pinv-joint", "pinv-actuator", "min-flow", "min-ls-power"});
  EXPECT_FALSE(dynamics::parse_resolution(config::kEnergyOptimal).has_value());
  EXPECT_EQ(config::resolution_names(),
            (std::vector<std::string>{"energy-optimal", "pinv-joint", "pinv-actuator", "min-flow",
                                      "min-ls-power"}));
}

TEST(EnumNames, BackendKind) {
  expect_round_trip(config::kBackendKinds, config::parse_backend_kind, {"sim", "can"});
}

TEST(EnumNames, TelemetryQos) {
  expect_round_trip(config::kReliabilities, config::parse_reliability, {"best_effort", "reliable"});
  expect_round_trip(config::kDurabilities, config::parse_durability,
                    {"volatile", "transient_local"});
  expect_round_trip(config::kDdsTransports, config::parse_dds_transport, {"default", "udp", "shm"});
}

TEST(EnumNames, CommandLineOnly) {
  expect_round_trip(control::kScalingModes, control::parse_scaling_mode, {"full", "flow", "none"});
  expect_round_trip(studies::kStartExtensions, studies::parse_start_extension,
                    {"shortest", "middle"});
  expect_round_trip(planner::kPlanCosts, planner::parse_plan_cost,
                    {"ls", "cp", "actuator-energy", "extension"});
  EXPECT_EQ(studies::plan_methods(), (std::vector<std::string>{"dp", "pinv-joint", "pinv-actuator",
                                                               "min-flow", "min-ls-power"}));
  for (const std::string& method : studies::plan_methods())
    EXPECT_TRUE(studies::is_plan_method(method));
  EXPECT_FALSE(studies::is_plan_method("energy-optimal"));
}

TEST(EnumNames, AlternativesForMessages) {
  EXPECT_EQ(alternatives(config::kBackendKinds), "sim or can");
  EXPECT_EQ(alternatives(dynamics::kPowerBounds), "load_sensing, actuator_sum or none");
  EXPECT_EQ(alternatives(dynamics::kResolutions),
            "pinv-joint, pinv-actuator, min-flow or min-ls-power");
}

TEST(EnumNames, ConfigMessagesListTheNames) {
  // The messages a config file with an unknown name gets (docs/config.md).
  std::ifstream in(std::string(CRANEASSIST_SOURCE_DIR) + "/config/cranes/k70m.yaml");
  std::stringstream text;
  text << in.rdbuf();
  const std::string k70m = text.str();
  ASSERT_FALSE(k70m.empty());
  const auto message = [&k70m](const std::string& from, const std::string& to) {
    std::string yaml = k70m;
    const std::size_t at = yaml.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    yaml.replace(at, from.size(), to);
    try {
      config::parse_crane_config(yaml, "k70m.yaml");
    } catch (const config::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("mode: load-sensing", "mode: cp")
                .find("field 'hydraulics.pump.mode': expected load-sensing or constant-pressure, "
                      "got 'cp'"),
            std::string::npos);
  EXPECT_NE(message("power_bound: load_sensing", "power_bound: ls")
                .find("field 'scaling.power_bound': expected load_sensing, actuator_sum or none, "
                      "got 'ls'"),
            std::string::npos);
  EXPECT_NE(message("backend: sim", "backend: warp")
                .find("field 'backend': unknown backend 'warp' (expected sim or can)"),
            std::string::npos);
  EXPECT_NE(message("resolution: energy-optimal", "resolution: min-fuel")
                .find("field 'redundancy.resolution': expected energy-optimal, pinv-joint, "
                      "pinv-actuator, min-flow or min-ls-power, got 'min-fuel'"),
            std::string::npos);
}

}  // namespace
}  // namespace craneassist
