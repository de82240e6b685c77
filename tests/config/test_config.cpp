// Config loading: the shipped models, and every kind of error naming file, line and field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>

#include "config_edit.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/config/quantity.hpp"
#include "craneassist/config/yaml_reader.hpp"
#include "thrown_error.hpp"

using craneassist::config::ConfigError;
using craneassist::config::Dimension;

namespace {

using craneassist::test::read_text_file;

const std::string kK70mPath = std::string(CRANEASSIST_SOURCE_DIR) + "/config/cranes/k70m.yaml";

// Replaces the first occurrence of `from` in the K70M file and parses the result; returns the
// error it throws.
ConfigError error_after_edit(const std::string& from, const std::string& to) {
  return craneassist::test::crane_config_error_after_edit(kK70mPath, from, to);
}

// Replaces the first occurrence of `from` in the K70M file and parses the result.
craneassist::config::CraneConfig config_after_edit(const std::string& from, const std::string& to) {
  return craneassist::config::parse_crane_config(
      craneassist::test::edited_text(kK70mPath, from, to), "edited.yaml");
}

int line_of(const std::string& needle) {
  const std::string text = read_text_file(kK70mPath);
  const auto pos = text.find(needle);
  return 1 +
         static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n'));
}

}  // namespace

TEST(Quantity, ParsesValuesUnitsAndSource) {
  std::string err;
  auto q = craneassist::config::parse_quantity("325 L/min, paper", Dimension::kFlow, err);
  ASSERT_TRUE(q) << err;
  EXPECT_NEAR(q->si_values[0], 325e-3 / 60.0, 1e-15);
  EXPECT_EQ(q->source, craneassist::config::Source::kPaper);
  q = craneassist::config::parse_quantity("0 0 -9.81 m/s^2, standard", Dimension::kAcceleration,
                                          err);
  ASSERT_TRUE(q) << err;
  EXPECT_EQ(q->si_values.size(), 3u);
  q = craneassist::config::parse_quantity("90 deg", Dimension::kAngle, err);
  ASSERT_TRUE(q);
  EXPECT_NEAR(q->si_values[0], M_PI_2, 1e-15);
  EXPECT_EQ(q->source, craneassist::config::Source::kUnstated);
  EXPECT_FALSE(craneassist::config::parse_quantity("12 MPa", Dimension::kFlow, err));
  EXPECT_NE(err.find("not a volume flow unit"), std::string::npos) << err;
  EXPECT_FALSE(craneassist::config::parse_quantity("nan m", Dimension::kLength, err));
  EXPECT_FALSE(craneassist::config::parse_quantity("1.0x m", Dimension::kLength, err));
  EXPECT_FALSE(craneassist::config::parse_quantity("1 m, guessed", Dimension::kLength, err));
  EXPECT_FALSE(craneassist::config::parse_quantity("1", Dimension::kLength, err));
  EXPECT_FALSE(craneassist::config::parse_quantity("1 m m", Dimension::kLength, err));
  // A unit written against its number, as people type on a command line.
  q = craneassist::config::parse_quantity("-125deg", Dimension::kAngle, err);
  ASSERT_TRUE(q) << err;
  EXPECT_NEAR(q->si_values[0], -125.0 * M_PI / 180.0, 1e-15);
  q = craneassist::config::parse_quantity("21.5MPa, paper", Dimension::kPressure, err);
  ASSERT_TRUE(q) << err;
  EXPECT_NEAR(q->si_values[0], 21.5e6, 1e-6);
  q = craneassist::config::parse_quantity("1e-3m", Dimension::kLength, err);
  ASSERT_TRUE(q) << err;
  EXPECT_NEAR(q->si_values[0], 1e-3, 1e-18);
  EXPECT_FALSE(craneassist::config::parse_quantity("2e", Dimension::kLength, err));
  EXPECT_FALSE(craneassist::config::parse_quantity("1mm m", Dimension::kLength, err));
  EXPECT_FALSE(craneassist::config::parse_quantity("deg5", Dimension::kAngle, err));
}

TEST(CraneConfig, ReferenceCraneMatchesTheSpec) {
  const auto cfg = craneassist::config::load_crane_config(kK70mPath);
  const auto& m = cfg.model;
  ASSERT_EQ(m.dof(), 4);
  EXPECT_EQ(cfg.unsourced_quantities, 0) << "every shipped value must say where it comes from";
  EXPECT_NEAR(m.cylinders[1].area_a_m2, 11.31e-3, 0.01e-3);
  EXPECT_NEAR(m.cylinders[1].area_b_m2, 7.46e-3, 0.01e-3);
  EXPECT_NEAR(m.cylinders[2].area_a_m2, 10.39e-3, 0.01e-3);
  EXPECT_NEAR(m.cylinders[2].area_b_m2, 7.56e-3, 0.01e-3);
  EXPECT_NEAR(m.cylinders[3].area_a_m2, 3.848e-3, 0.001e-3);
  EXPECT_NEAR(m.cylinders[3].area_b_m2, 2.258e-3, 0.001e-3);
  EXPECT_TRUE(m.cylinders[3].differential_spool);
  EXPECT_NEAR(m.pump.max_flow_m3_s, 325e-3 / 60, 1e-12);
  EXPECT_NEAR(m.pump.prime_mover_power_w, 35e3, 1e-9);
  EXPECT_EQ(m.pump.mode, craneassist::dynamics::PumpMode::kLoadSensing);
  EXPECT_NEAR(m.pump.supply_pressure_pa, 20e6, 1e-6);
  EXPECT_NEAR(m.valves.dead_zone, 0.53, 1e-12);
  EXPECT_NEAR(m.joints[1].q_max, 1.097, 1e-12);
  EXPECT_NEAR(m.joints[2].theta_rad, M_PI_2, 1e-12);
  EXPECT_EQ(m.bodies.back().name, "payload");
  EXPECT_EQ(m.bodies.back().frame, 4);
  EXPECT_NEAR(cfg.control.rate_hz, 100.0, 1e-12);
  EXPECT_NEAR(cfg.simulation.step_s, 1e-3, 1e-15);
}

TEST(CraneConfig, EmbeddedModelsEqualTheFiles) {
  const auto embedded = craneassist::config::default_crane_config();
  const auto file = craneassist::config::load_crane_config(kK70mPath);
  EXPECT_EQ(embedded.model.name, file.model.name);
  EXPECT_EQ(embedded.model.bodies.size(), file.model.bodies.size());
  const auto planar = craneassist::config::planar_2r_config();
  EXPECT_EQ(planar.model.dof(), 2);
  EXPECT_EQ(planar.unsourced_quantities, 0);
}

TEST(CraneConfig, BadUnitNamesLineAndField) {
  const auto e = error_after_edit("bore: 120 mm, paper", "bore: 120 mmm, paper");
  EXPECT_EQ(e.file(), "edited.yaml");
  EXPECT_EQ(e.line(), line_of("bore: 120 mm, paper"));
  EXPECT_EQ(e.field(), "joints[1].cylinder.bore");
  EXPECT_NE(std::string(e.what()).find("edited.yaml:"), std::string::npos);
}

TEST(CraneConfig, MissingFieldNamesTheField) {
  const auto e = error_after_edit("    max_flow: 325 L/min, paper        # at 2500 rpm\n", "");
  EXPECT_EQ(e.field(), "hydraulics.pump.max_flow");
  EXPECT_GT(e.line(), 0);
}

TEST(CraneConfig, UnknownFieldIsATypo) {
  const auto e = error_after_edit("stroke: 610 mm, paper", "strok: 610 mm, paper");
  EXPECT_EQ(e.field(), "joints[1].cylinder.strok");
  EXPECT_EQ(e.line(), line_of("stroke: 610 mm, paper"));
}

TEST(CraneConfig, WrongDimensionIsRejected) {
  const auto e = error_after_edit("max_flow: 325 L/min", "max_flow: 325 MPa");
  EXPECT_EQ(e.field(), "hydraulics.pump.max_flow");
  EXPECT_NE(e.reason().find("L/min"), std::string::npos) << e.reason();
}

TEST(CraneConfig, OutOfRangeValuesAreRejected) {
  EXPECT_EQ(error_after_edit("dead_zone: 0.53", "dead_zone: 1.5").field(),
            "hydraulics.valves.dead_zone");
  EXPECT_EQ(
      error_after_edit("mass: 0 kg, assumed\n\nhydraulics", "mass: -5 kg, assumed\n\nhydraulics")
          .field(),
      "payload.mass");
  EXPECT_EQ(error_after_edit("lift: 20 deg", "lift: 80 deg").field(), "simulation.initial.lift");
  EXPECT_EQ(error_after_edit("step: 1 ms", "step: 3 ms").field(), "simulation.step");
}

// The simulated machine's valves, joint sensors and feedback where they differ from the model
// (docs/valves.md#the-machine-it-meets): every section's fields, then a joint's own; refused with
// the line and field.
TEST(CraneConfig, SimulatedMachineDeviations) {
  const std::string anchor = "  return_pressure: 0.3 MPa, assumed";
  const auto cfg = config_after_edit(
      anchor,
      anchor +
          "\n  valves:\n    time_constant: 25 ms\n    dead_zone: 0.4\n    lift: {gain: 1.2, "
          "shape: 1.5, hysteresis: 0.02, delay: 0.17 s}\n"
          "  joint_sensors: {angle_resolution: 0.01 deg, length_noise: 1 mm, delay: 5 ms}\n"
          "  feedback: {delay: 10 ms, jitter: 4 ms}");
  for (int i = 0; i < cfg.model.dof(); ++i) {
    const auto& v = cfg.simulation.valves[static_cast<std::size_t>(i)];
    EXPECT_DOUBLE_EQ(v.time_constant_s, 0.025) << i;
    EXPECT_DOUBLE_EQ(v.dead_zone, 0.4) << i;
    EXPECT_EQ(v.gain, i == 1 ? 1.2 : 1.0) << i;
    EXPECT_EQ(v.shape, i == 1 ? 1.5 : 1.0) << i;
    EXPECT_EQ(v.hysteresis, i == 1 ? 0.02 : 0.0) << i;
    EXPECT_EQ(std::isnan(v.delay_s), i != 1) << i;
  }
  EXPECT_DOUBLE_EQ(cfg.simulation.valves[1].delay_s, 0.17);
  const auto& js = cfg.simulation.joints;
  EXPECT_NEAR(js.angle_resolution_rad, 0.01 * M_PI / 180.0, 1e-15);
  EXPECT_DOUBLE_EQ(js.length_noise_m, 0.001);
  EXPECT_DOUBLE_EQ(js.delay_s, 0.005);
  EXPECT_DOUBLE_EQ(js.feedback_delay_s, 0.01);
  EXPECT_DOUBLE_EQ(js.feedback_jitter_s, 0.004);
  EXPECT_TRUE(craneassist::config::default_crane_config().simulation.joints.exact())
      << "left out: exact";

  const auto joint = error_after_edit(anchor, anchor + "\n  valves:\n    boom: {gain: 2}");
  EXPECT_EQ(joint.field(), "simulation.valves.boom");
  EXPECT_EQ(joint.line(), line_of(anchor) + 2);
  const auto range = error_after_edit(anchor, anchor + "\n  valves:\n    lift: {gain: 20}");
  EXPECT_EQ(range.field(), "simulation.valves.lift.gain");
  EXPECT_EQ(error_after_edit(anchor, anchor + "\n  valves: {dead_zone: 0.99}").field(),
            "simulation.valves.dead_zone");
  EXPECT_EQ(error_after_edit(anchor, anchor + "\n  feedback: {delay: 10 ms, late: 1 s}").field(),
            "simulation.feedback.late");
  EXPECT_EQ(error_after_edit(anchor, anchor + "\n  joint_sensors: {delay: 2 s}").field(),
            "simulation.joint_sensors.delay");
}

// The stop and the valves' slew-rate limit (docs/safety.md, docs/valves.md): read, defaulted
// when left out, and refused out of range naming the line and field.
TEST(CraneConfig, StopAndSlewRateSettings) {
  const auto cfg = config_after_edit("rest_timeout: 2 s", "rest_timeout: 1.5 s");
  EXPECT_DOUBLE_EQ(cfg.model.valves.stroke_time_s, 0.05);
  EXPECT_DOUBLE_EQ(cfg.control.rest_speed_m_s, 0.005);
  EXPECT_DOUBLE_EQ(cfg.control.rest_timeout_s, 1.5);
  EXPECT_TRUE(std::isnan(cfg.simulation.valves[0].time_constant_s)) << "left out: the model's";
  const auto without = config_after_edit("    stroke_time: 0.05 s, assumed\n", "");
  EXPECT_EQ(without.model.valves.stroke_time_s, 0.0) << "left out: no limit";
  const auto machine = config_after_edit("  return_pressure: 0.3 MPa, assumed",
                                         "  return_pressure: 0.3 MPa, assumed\n"
                                         "  spool_time_constant: 80 ms, assumed");
  for (int i = 0; i < machine.model.dof(); ++i) {
    EXPECT_DOUBLE_EQ(machine.simulation.valves[static_cast<std::size_t>(i)].time_constant_s, 0.08);
  }
  const auto stroke = error_after_edit("stroke_time: 0.05 s", "stroke_time: 7 s");
  EXPECT_EQ(stroke.field(), "hydraulics.valves.stroke_time");
  EXPECT_EQ(stroke.line(), line_of("stroke_time: 0.05 s"));
  EXPECT_EQ(error_after_edit("rest_speed: 5 mm/s", "rest_speed: 0 mm/s").field(),
            "control.rest_speed");
  EXPECT_EQ(error_after_edit("rest_speed: 5 mm/s", "rest_speed: 5 s").field(),
            "control.rest_speed");
  EXPECT_EQ(error_after_edit("rest_timeout: 2 s", "rest_timeout: 9 s").field(),
            "control.rest_timeout");
}

// The geometry, masses, inertias and gravity are checked against ranges in which the simulator
// and the dynamics model run (docs/config.md#ranges; the edges run in test_replay_e2e): values
// they cannot take (a 1e30 m link, gravity -1000) were accepted and aborted the run in ODE or
// ran it into nonsense. Each is refused naming its line and field.
TEST(CraneConfig, GeometryMassesAndGravityOutsideTheirRangesAreRejected) {
  struct Case {
    std::string from, to, field, reason_part;
  };
  const Case cases[] = {
      {"    a: 3.504 m, paper", "    a: 1e30 m, paper", "joints[1].a", "within +-100 m"},
      {"    a: 3.504 m, paper", "    a: 100.1 m, paper", "joints[1].a", "within +-100 m"},
      {"    d: 1.605 m, paper", "    d: -101 m, paper", "joints[0].d", "within +-100 m"},
      {"    alpha: 90 deg, paper", "    alpha: 361 deg, paper", "joints[0].alpha", "+-360 deg"},
      {"    theta_offset: 90 deg, paper", "    theta_offset: -1e9 deg, paper",
       "joints[2].theta_offset", "+-360 deg"},
      {"    max: 3.7 m, paper", "    max: 150 m, paper", "joints[3].max", "within +-100 m"},
      {"      length_at_zero: 0.36 m, assumed", "      length_at_zero: 1e30 m, assumed",
       "joints[0].cylinder.length_at_zero", "within +-100 m"},
      {"      arm: 0.5 m, paper", "      arm: 200 m, paper", "joints[3].cylinder.arm",
       "within +-100 m"},
      {"      l1: 0.44 m, assumed", "      l1: 101 m, assumed", "joints[1].cylinder.l1",
       "at most 100 m"},
      {"      angle_offset: 1.01 rad, assumed", "      angle_offset: 100 rad, assumed",
       "joints[1].cylinder.angle_offset", "+-360 deg"},
      {"-0.23441829 1.08923838 m", "-0.23441829 1e9 m", "joints[2].cylinder.coefficients",
       "cylinder length leaves +-100 m"},
      {"    mass: 420 kg, assumed", "    mass: 0.5 kg, assumed", "bodies[1].mass",
       "between 1 kg and 100000 kg"},
      {"    mass: 420 kg, assumed", "    mass: 2e5 kg, assumed", "bodies[1].mass",
       "between 1 kg and 100000 kg"},
      {"    com: -1.754 0 0 m, assumed", "    com: -1e20 0 0 m, assumed", "bodies[1].com",
       "each must be within +-100 m"},
      {"    inertia: 10 429 429 kg*m^2", "    inertia: 1e30 429 429 kg*m^2", "bodies[1].inertia",
       "radius of gyration 1 cm to 30 m"},
      {"    inertia: 10 429 429 kg*m^2", "    inertia: 0 429 429 kg*m^2", "bodies[1].inertia",
       "between m (1 cm)^2 and m (30 m)^2, 0.042 to 378000 kg*m^2"},
      {"    inertia: 10 429 429 kg*m^2", "    inertia: 10 429 500 kg*m^2", "bodies[1].inertia",
       "principal moment 3 (500 kg*m^2) exceeds the sum of the other two (439 kg*m^2)"},
      {"gravity: 0 0 -9.81 m/s^2", "gravity: 0 0 -1000 m/s^2", "frames.gravity",
       "magnitude 1000 m/s^2 must be at most 20 m/s^2"},
      {"gravity: 0 0 -9.81 m/s^2", "gravity: 0 0 9.81 m/s^2", "frames.gravity",
       "must point down, within 45 deg of the crane frame's -y"},
      {"gravity: 0 0 -9.81 m/s^2", "gravity: 9.81 0 -8 m/s^2", "frames.gravity", "it is 50.8"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.to);
    const auto e = error_after_edit(c.from, c.to);
    EXPECT_EQ(e.field(), c.field) << e.what();
    EXPECT_EQ(e.line(), line_of(c.from)) << e.what();
    EXPECT_NE(e.reason().find(c.reason_part), std::string::npos) << e.what();
  }
  // At the edges the file loads; zero gravity has no direction to check.
  EXPECT_NO_THROW(config_after_edit("gravity: 0 0 -9.81 m/s^2", "gravity: 0 0 0 m/s^2"));
  EXPECT_NO_THROW(config_after_edit("gravity: 0 0 -9.81 m/s^2", "gravity: 14.14 0 -14.14 m/s^2"));
  EXPECT_NO_THROW(config_after_edit("    inertia: 10 429 429", "    inertia: 4.2e-2 429 429"));
  EXPECT_NO_THROW(config_after_edit("    inertia: 10 429 429", "    inertia: 200 200 400"));
}

TEST(CraneConfig, ConstantPressurePumpIsParsed) {
  using craneassist::dynamics::PumpMode;
  const auto cp = config_after_edit("mode: load-sensing", "mode: constant-pressure");
  EXPECT_EQ(cp.model.pump.mode, PumpMode::kConstantPressure);
  EXPECT_NEAR(cp.model.pump.supply_pressure_pa, 20e6, 1e-6);
  EXPECT_EQ(cp.unsourced_quantities, 0);
  const auto bar = config_after_edit("supply_pressure: 20 MPa, paper", "supply_pressure: 180 bar");
  EXPECT_NEAR(bar.model.pump.supply_pressure_pa, 18e6, 1e-6);
  EXPECT_EQ(bar.unsourced_quantities, 1);
  // Both fields are optional in load-sensing mode; the mode defaults to load sensing.
  auto text = read_text_file(kK70mPath);
  for (const std::string line : {"    mode: load-sensing", "    supply_pressure: 20 MPa"}) {
    const auto pos = text.find(line);
    ASSERT_NE(pos, std::string::npos) << line;
    text.erase(pos, text.find('\n', pos) + 1 - pos);
  }
  const auto bare = craneassist::config::parse_crane_config(text, "bare.yaml");
  EXPECT_EQ(bare.model.pump.mode, PumpMode::kLoadSensing);
  EXPECT_EQ(bare.model.pump.supply_pressure_pa, 0.0);
}

TEST(CraneConfig, BadPumpModeNamesLineFieldAndTheAcceptedValues) {
  const auto e = error_after_edit("mode: load-sensing", "mode: load_sensing");
  EXPECT_EQ(e.file(), "edited.yaml");
  EXPECT_EQ(e.line(), line_of("mode: load-sensing"));
  EXPECT_EQ(e.field(), "hydraulics.pump.mode");
  EXPECT_NE(e.reason().find("expected load-sensing or constant-pressure, got 'load_sensing'"),
            std::string::npos)
      << e.reason();
}

TEST(CraneConfig, SupplyPressureMustBePositiveAndWithinTheRelief) {
  const auto above = error_after_edit("supply_pressure: 20 MPa", "supply_pressure: 22 MPa");
  EXPECT_EQ(above.field(), "hydraulics.pump.supply_pressure");
  EXPECT_EQ(above.line(), line_of("supply_pressure: 20 MPa"));
  EXPECT_NE(above.reason().find("at most max_pressure"), std::string::npos) << above.reason();
  EXPECT_NE(std::string(above.what()).find("edited.yaml:"), std::string::npos);
  EXPECT_EQ(error_after_edit("supply_pressure: 20 MPa", "supply_pressure: 0 MPa").field(),
            "hydraulics.pump.supply_pressure");
  EXPECT_EQ(error_after_edit("supply_pressure: 20 MPa", "supply_pressure: 20 L/min").field(),
            "hydraulics.pump.supply_pressure");
  // At the relief setting exactly is allowed.
  EXPECT_NEAR(config_after_edit("supply_pressure: 20 MPa", "supply_pressure: 21.5 MPa")
                  .model.pump.supply_pressure_pa,
              21.5e6, 1e-6);
}

TEST(CraneConfig, ConstantPressureModeNeedsTheSupplyPressure) {
  std::string text = read_text_file(kK70mPath);
  text.replace(text.find("mode: load-sensing"), 18, "mode: constant-pressure");
  const auto pos = text.find("    supply_pressure: 20 MPa");
  text.erase(pos, text.find('\n', pos) + 1 - pos);
  try {
    craneassist::config::parse_crane_config(text, "edited.yaml");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.field(), "hydraulics.pump.supply_pressure");
    EXPECT_GT(e.line(), 0);
    EXPECT_NE(e.reason().find("missing"), std::string::npos) << e.reason();
  }
}

TEST(CraneConfig, JointRangeMustFitTheStroke) {
  const auto e = error_after_edit("stroke: 725 mm, paper", "stroke: 500 mm, paper");
  EXPECT_EQ(e.field(), "joints[2].cylinder.stroke");
  EXPECT_NE(e.reason().find("mm of stroke"), std::string::npos) << e.reason();
}

TEST(CraneConfig, YamlSyntaxErrorHasALine) {
  const auto e = error_after_edit("joints:\n", "joints: [\n");
  EXPECT_GT(e.line(), 0);
  EXPECT_NE(e.reason().find("YAML syntax"), std::string::npos);
}

// yaml-cpp keeps both entries of a repeated key and a lookup takes the first, so a second value
// would be silently ignored: it is an error at the second, naming the first's line. At the top
// level, in a section and in a list entry; an alias is not a repeat.
TEST(CraneConfig, DuplicateKeysAreRejected) {
  auto e = error_after_edit("  rate: 100 Hz, assumed\n",
                            "  rate: 100 Hz, assumed\n  rate: 7 Hz, assumed\n");
  EXPECT_EQ(std::string(e.what()), "edited.yaml:" + std::to_string(line_of("  rate: 100 Hz") + 1) +
                                       ": field 'control.rate': duplicate key (first at line " +
                                       std::to_string(line_of("  rate: 100 Hz")) + ")");
  e = error_after_edit("      stroke: 725 mm, paper\n",
                       "      stroke: 725 mm, paper\n      stroke: 500 mm, paper\n");
  EXPECT_EQ(e.field(), "joints[2].cylinder.stroke");
  EXPECT_EQ(e.line(), line_of("      stroke: 725 mm") + 1);
  e = error_after_edit("backend: sim\n", "backend: sim\nbackend: can\n");
  EXPECT_EQ(e.field(), "backend");
  EXPECT_EQ(e.reason(),
            "duplicate key (first at line " + std::to_string(line_of("backend: sim")) + ")");
  // A mapping reached twice through an anchor and its alias is no repeat, and a node that
  // contains itself (yaml-cpp builds the cycle) is walked once.
  const YAML::Node aliased = YAML::Load("a: &m {x: 1, y: 2}\nb: *m\nc: [*m, *m]\nd: &s [*s]\n");
  EXPECT_NO_THROW(craneassist::config::check_unique_keys(aliased, "aliased.yaml"));
  try {
    craneassist::config::check_unique_keys(YAML::Load("a:\n  - {x: 1}\n  - {x: 1, x: 2}\n"),
                                           "list.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& list_error) {
    EXPECT_EQ(std::string(list_error.what()),
              "list.yaml:3: field 'a[1].x': duplicate key (first at line 3)");
  }
}

TEST(CraneConfig, MissingFileIsReported) {
  try {
    craneassist::config::load_crane_config("/nonexistent/crane.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "/nonexistent/crane.yaml");
    EXPECT_EQ(e.line(), 0);
  }
}

// A config is read with the YAML files' bound (1 MiB): a larger file, or one without an end
// (/dev/zero), is refused naming the file, not read until the memory runs out.
TEST(CraneConfig, AFileOverTheSizeLimitIsRefused) {
  const std::string big = ::testing::TempDir() + "craneassist_big_crane.yaml";
  {
    std::ofstream out(big, std::ios::binary);
    out << read_text_file(kK70mPath);
    while (out.tellp() <= static_cast<std::streamoff>(1 << 20)) {
      out << "# a comment line that makes the file larger than the limit\n";
    }
  }
  for (const std::string& file : {big, std::string("/dev/zero")}) {
    try {
      craneassist::config::load_crane_config(file);
      ADD_FAILURE() << "accepted " << file;
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()),
                file + ": larger than 1 MiB (the limit for crane config files)");
      EXPECT_EQ(e.line(), 0);
    }
  }
  std::remove(big.c_str());
}

// The fields the command line overrides are set through the config's own range check: the same
// range and reason as the file's error, and an out-of-range value leaves the field as it was.
TEST(CraneConfig, OverridesHaveTheFieldsRanges) {
  using namespace craneassist::config;
  auto cfg = default_crane_config();
  const auto reason_of = [](auto&& set) {
    try {
      set();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const double l_min = 1e-3 / 60.0;
  EXPECT_EQ(reason_of([&] { set_pump_max_flow(cfg.model, 1e30 * l_min); }),
            error_after_edit("max_flow: 325 L/min", "max_flow: 1e30 L/min").reason());
  EXPECT_EQ(reason_of([&] { set_pump_max_flow(cfg.model, 0.0); }),
            "must be positive and at most 60000 L/min (1 m^3/s)");
  EXPECT_NEAR(cfg.model.pump.max_flow_m3_s, 325 * l_min, 1e-12);  // unchanged
  EXPECT_EQ(reason_of([&] { set_pump_max_flow(cfg.model, 100 * l_min); }), "accepted");
  EXPECT_NEAR(cfg.model.pump.max_flow_m3_s, 100 * l_min, 1e-12);
  EXPECT_EQ(reason_of([&] { set_prime_mover_power(cfg.model, 1e30); }),
            error_after_edit("prime_mover_power: 35 kW", "prime_mover_power: 1e30 W").reason());
  EXPECT_EQ(reason_of([&] { set_prime_mover_power(cfg.model, 60e3); }), "accepted");
  EXPECT_EQ(reason_of([&] { set_supply_pressure(cfg.model, -1.0); }),
            error_after_edit("supply_pressure: 20 MPa", "supply_pressure: -1 Pa").reason());
  EXPECT_EQ(reason_of([&] { set_supply_pressure(cfg.model, 25e6); }),
            "must be positive and at most max_pressure (the relief setting, 21.5 MPa)");
  EXPECT_EQ(
      reason_of([&] { set_payload_mass(cfg.model, 1e6); }),
      error_after_edit("mass: 0 kg, assumed\n\nhydraulics", "mass: 1e6 kg, assumed\n\nhydraulics")
          .reason());
  EXPECT_EQ(reason_of([&] { set_can_feedback_timeout(cfg.backend, 30.0); }),
            error_after_edit("feedback_timeout: 50 ms", "feedback_timeout: 30 s").reason());
  EXPECT_EQ(reason_of([&] { set_can_feedback_timeout(cfg.backend, 0.002); }), "accepted");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(reason_of([&] { set_pump_max_flow(cfg.model, nan); }), "accepted");
  EXPECT_NE(reason_of([&] { set_supply_pressure(cfg.model, nan); }), "accepted");
  EXPECT_NE(reason_of([&] { set_payload_mass(cfg.model, nan); }), "accepted");
}

TEST(CraneConfig, PayloadMassCanBeSet) {
  auto cfg = craneassist::config::default_crane_config();
  craneassist::config::set_payload_mass(cfg.model, 650.0);
  EXPECT_DOUBLE_EQ(cfg.model.bodies.back().mass_kg, 650.0);
  EXPECT_THROW(craneassist::config::set_payload_mass(cfg.model, -1.0), std::invalid_argument);
}

TEST(CraneConfig, BackendAndCanSettings) {
  using craneassist::config::BackendKind;
  const auto shipped = craneassist::config::load_crane_config(kK70mPath);
  EXPECT_EQ(shipped.backend.kind, BackendKind::kSim);
  EXPECT_EQ(shipped.backend.can.interface, "can0");
  EXPECT_TRUE(shipped.backend.can.mapping.empty());  // the embedded K70M mapping
  EXPECT_DOUBLE_EQ(shipped.backend.can.feedback_timeout_s, 0.05);

  const auto can = config_after_edit("backend: sim", "backend: can");
  EXPECT_EQ(can.backend.kind, BackendKind::kCan);
  // A relative mapping path is resolved against the config file's folder.
  std::string text = read_text_file(kK70mPath);
  text.replace(text.find("  # mapping:"), 12, "  mapping:");
  const auto mapped = craneassist::config::parse_crane_config(text, "/etc/crane/k70m.yaml");
  EXPECT_EQ(mapped.backend.can.mapping, "/etc/crane/../can/k70m_can.yaml");

  // Both may be left out: sim.
  text = read_text_file(kK70mPath);
  text.erase(text.find("backend: sim"));
  EXPECT_EQ(craneassist::config::parse_crane_config(text, "bare.yaml").backend.kind,
            BackendKind::kSim);

  const auto bad = error_after_edit("backend: sim", "backend: ros");
  EXPECT_EQ(bad.field(), "backend");
  EXPECT_EQ(bad.line(), line_of("backend: sim"));
  EXPECT_NE(bad.reason().find("expected sim or can"), std::string::npos) << bad.reason();
  EXPECT_EQ(error_after_edit("interface: can0", "interface: can0/x").field(), "can.interface");
  EXPECT_EQ(error_after_edit("feedback_timeout: 50 ms", "feedback_timeout: 5 s").field(),
            "can.feedback_timeout");
  EXPECT_EQ(error_after_edit("interface: can0", "iface: can0").field(), "can.iface");
}

TEST(CraneConfig, EnergyOptimalFollowsThePumpMode) {
  using craneassist::dynamics::PumpMode;
  using craneassist::dynamics::Resolution;
  auto cfg = craneassist::config::default_crane_config();
  EXPECT_TRUE(cfg.redundancy.energy_optimal);
  EXPECT_EQ(cfg.redundancy.resolution, Resolution::kMinLsPower);
  EXPECT_EQ(craneassist::config::resolution_description(cfg),
            "min-ls-power (energy-optimal for load sensing)");
  cfg.model.pump.mode = PumpMode::kConstantPressure;
  craneassist::config::apply_energy_optimal(cfg);
  EXPECT_EQ(cfg.redundancy.resolution, Resolution::kMinFlow);
  // A named resolution stays what it is.
  craneassist::config::set_resolution(cfg, "pinv-actuator");
  EXPECT_FALSE(cfg.redundancy.energy_optimal);
  cfg.model.pump.mode = PumpMode::kLoadSensing;
  craneassist::config::apply_energy_optimal(cfg);
  EXPECT_EQ(cfg.redundancy.resolution, Resolution::kPinvActuator);
  // In the file, a constant-pressure pump makes energy-optimal min-flow.
  const auto cp = config_after_edit("mode: load-sensing ", "mode: constant-pressure ");
  EXPECT_EQ(cp.redundancy.resolution, Resolution::kMinFlow);
}

TEST(CraneConfig, BadResolutionNamesLineFieldAndTheChoices) {
  const auto e = error_after_edit("resolution: energy-optimal", "resolution: fastest");
  EXPECT_EQ(e.field(), "redundancy.resolution");
  EXPECT_EQ(e.line(), line_of("resolution: energy-optimal"));
  EXPECT_NE(e.reason().find("energy-optimal, pinv-joint"), std::string::npos) << e.reason();
  auto two = craneassist::config::planar_2r_config();
  EXPECT_THROW(craneassist::config::set_resolution(two, "energy-optimal"), std::invalid_argument);
  EXPECT_NO_THROW(craneassist::config::set_resolution(two, "pinv-joint"));
}

TEST(JointPose, NamedJointsWithUnitsOverrideTheBase) {
  const auto cfg = craneassist::config::default_crane_config();
  const auto q = craneassist::config::parse_joint_pose(
      cfg.model, "lift=0 deg, tilt = -125 deg ,extension=200 mm", cfg.simulation.q_initial);
  EXPECT_EQ(q[0], cfg.simulation.q_initial[0]);
  EXPECT_NEAR(q[1], 0.0, 1e-15);
  EXPECT_NEAR(q[2], -125.0 * M_PI / 180.0, 1e-12);
  EXPECT_NEAR(q[3], 0.2, 1e-15);
  EXPECT_NEAR(
      craneassist::config::parse_joint_pose(cfg.model, "slew=0.5 rad", cfg.simulation.q_initial)[0],
      0.5, 1e-15);
}

TEST(JointPose, EveryMistakeIsNamed) {
  const auto cfg = craneassist::config::default_crane_config();
  auto reason = [&](const char* text) {
    try {
      craneassist::config::parse_joint_pose(cfg.model, text, cfg.simulation.q_initial);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(reason("boom=1 rad").find("'boom': no joint of that name (the joints: slew, lift"),
            std::string::npos);
  EXPECT_NE(reason("lift=2 rad").find("'lift': outside the joint range"), std::string::npos);
  EXPECT_NE(reason("lift=0.2").find("'lift': missing unit: an angle"), std::string::npos);
  EXPECT_NE(reason("extension=1 deg").find("'extension'"), std::string::npos);
  EXPECT_NE(reason("lift=0.1 rad, lift=0.2 rad").find("given twice"), std::string::npos);
  EXPECT_NE(reason("lift 0.1 rad").find("expected NAME=VALUE UNIT"), std::string::npos);
  EXPECT_NE(reason("").find("no joint given"), std::string::npos);
  EXPECT_NE(reason("lift=0.1 rad,,tilt=-1 rad").find("empty part"), std::string::npos);
  EXPECT_NE(reason("lift=nan rad").find("'lift'"), std::string::npos);
}
