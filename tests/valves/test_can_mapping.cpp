// The CAN mapping file: the shipped example loads with its values in SI, and every kind of
// mistake is reported with file, line and field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <string>

#include "craneassist/can/mapping_config.hpp"
#include "craneassist/config/config_error.hpp"
#include "craneassist/config/crane_config.hpp"
#include "thrown_error.hpp"

using namespace craneassist::can;
using craneassist::config::ConfigError;

namespace {

const std::string kExample = std::string(CRANEASSIST_SOURCE_DIR) + "/config/can/k70m_can.yaml";

// A minimal valid file; `joint` replaces the first joint's body.
std::string file_with(const std::string& joint) {
  return "format: craneassist-can-map/1\n"
         "joints:\n"
         "  - name: slew\n" +
         joint;
}

const std::string kValve =
    "    valve:\n"
    "      iso11783_avc: {valve: 0, source_address: 0x80, cycle: 20 ms}\n";
const std::string kPosition =
    "    position: {id: 0x18FF1021, extended: true, start_bit: 0, length: 16,\n"
    "               byte_order: intel, signed: true, scale: 0.01, unit: deg}\n";

// Parses text expecting a ConfigError; returns it.
ConfigError error_of(const std::string& text) {
  return craneassist::test::thrown_error<ConfigError>([&] { parse_can_mapping(text, "map.yaml"); },
                                                      "no error for:\n" + text);
}

}  // namespace

TEST(CanMapping, ShippedExampleLoads) {
  const CanMapping m = load_can_mapping(kExample);
  ASSERT_EQ(m.joints.size(), 4u);
  const JointMapping& slew = m.joints[0];
  EXPECT_EQ(slew.name, "slew");
  ASSERT_EQ(slew.valve.kind, ValveOutputKind::kIso11783Avc);
  EXPECT_EQ(slew.valve.avc.valve, 0);
  EXPECT_EQ(slew.valve.avc.source_address, 0x80);
  EXPECT_EQ(slew.valve.avc.priority, 3);
  EXPECT_DOUBLE_EQ(slew.valve.avc.cycle_s, 0.02);
  EXPECT_EQ(slew.valve.avc.fail_safe, iso11783::FailSafeMode::kBlock);
  EXPECT_TRUE(slew.position.extended);
  EXPECT_EQ(slew.position.id, 0x18FF1021u);
  EXPECT_EQ(slew.position_kind, PositionKind::kAngle);
  EXPECT_NEAR(slew.position.scale, 0.01 * std::numbers::pi / 180.0, 1e-15);  // rad/bit
  EXPECT_EQ(slew.position.unit, "deg");
  ASSERT_TRUE(slew.pressure_a && slew.pressure_b);
  EXPECT_NEAR(slew.pressure_a->scale, 1000.0, 1e-9);  // 0.01 bar = 1000 Pa
  EXPECT_NEAR(*slew.pressure_a->maximum, 400e5, 1e-3);
  EXPECT_EQ(m.joints[2].position.byte_order, ByteOrder::kBigEndian);

  const JointMapping& ext = m.joints[3];
  ASSERT_EQ(ext.valve.kind, ValveOutputKind::kSignal);
  EXPECT_NEAR(ext.valve.signal.signal.scale, 1e-3, 1e-15);  // A/bit
  EXPECT_NEAR(*ext.valve.signal.signal.minimum, -0.8, 1e-12);
  EXPECT_EQ(ext.position_kind, PositionKind::kLength);
  EXPECT_NEAR(ext.position.scale, 1e-4, 1e-15);  // m/bit
  EXPECT_FALSE(ext.pressure_b.has_value());

  // A decoded slew encoder frame comes out in rad.
  CanFrame f;
  f.id = 0x18FF1021;
  f.extended = true;
  f.dlc = 8;
  f.data[0] = 0x28;  // 9000 = 0x2328 -> 90 deg
  f.data[1] = 0x23;
  double q = 0.0;
  ASSERT_EQ(decode(slew.position, f, q), SignalStatus::kOk);
  EXPECT_NEAR(q, std::numbers::pi / 2, 1e-12);
}

// A mapping that does not fit the crane is an input error naming the mapping's line and field,
// found before a bus is opened (it was found by CanBackend's constructor, after the command
// line had opened the bus, and exited 3).
TEST(CanMapping, MappingThatDoesNotFitTheCraneNamesLineAndField) {
  const auto crane = craneassist::config::default_crane_config().model;
  const std::string text = [] {
    std::ifstream in(kExample);
    return std::string{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }();
  EXPECT_NO_THROW(check_mapping_fits(parse_can_mapping(text, "k70m_can.yaml"), crane));
  const auto line_of = [&](const std::string& needle) {
    const auto at = text.find(needle);
    EXPECT_NE(at, std::string::npos) << needle;
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
  };
  const auto error_for = [&](const std::string& from, const std::string& to) {
    std::string edited = text;
    edited.replace(edited.find(from), from.size(), to);
    try {
      check_mapping_fits(parse_can_mapping(edited, "map.yaml"), crane);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string lift_position = "signed: true, scale: 0.01, unit: deg, min: -90, max: 90}";
  const std::string lift_line = std::to_string(line_of(lift_position) - 1);
  EXPECT_EQ(error_for(lift_position, "signed: true, scale: 0.01, unit: deg, min: -10, max: 90}"),
            "map.yaml:" + lift_line +
                ": field 'joints[1].position': joint 'lift': the position signal's min/max do not "
                "cover the joint range [-0.425, 1.097] rad");
  EXPECT_EQ(error_for("  - name: lift", "  - name: boom"),
            "map.yaml:" + std::to_string(line_of("  - name: lift")) +
                ": field 'joints[1].name': joint 2 is 'boom', the crane's is 'lift'");
  EXPECT_EQ(error_for(lift_position, "signed: true, scale: 0.01, unit: mm}"),
            "map.yaml:" + lift_line +
                ": field 'joints[1].position': joint 'lift': the crane's joint is revolute, its "
                "position signal's unit is a length");
  const auto planar = craneassist::config::planar_2r_config().model;
  try {
    check_mapping_fits(parse_can_mapping(text, "k70m_can.yaml"), planar);
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.line(), line_of("joints:"));
    EXPECT_EQ(e.field(), "joints");
    EXPECT_NE(e.reason().find("the mapping has 4 joints, the crane 2"), std::string::npos);
  }
}

TEST(CanMapping, MinimalFileAndDefaults) {
  const CanMapping m = parse_can_mapping(file_with(kValve + kPosition), "map.yaml");
  ASSERT_EQ(m.joints.size(), 1u);
  EXPECT_EQ(m.source, "map.yaml");
  EXPECT_TRUE(m.joints[0].valve.avc.extended_resolution);
  EXPECT_FALSE(m.joints[0].position.minimum.has_value());
  EXPECT_FALSE(m.joints[0].pressure_a.has_value());
}

TEST(CanMapping, ErrorsNameFileLineAndField) {
  struct Case {
    std::string text;
    int line;
    std::string field;
    std::string reason_part;
  };
  const std::string avc_head = "    valve:\n      iso11783_avc: ";
  const Case cases[] = {
      {"format: craneassist-can-map/2\njoints: []\n", 1, "format", "craneassist-can-map/1"},
      {"format: craneassist-can-map/1\n", 1, "joints", "missing"},
      {"format: craneassist-can-map/1\njoints: []\n", 2, "joints", "list of joints"},
      {"format: craneassist-can-map/1\nbus: x\njoints: []\n", 2, "bus", "unknown field"},
      {file_with(kPosition), 3, "joints[0].valve", "missing"},
      {file_with(avc_head + "{valve: 16, source_address: 0x80, cycle: 20 ms}\n" + kPosition), 5,
       "joints[0].valve.iso11783_avc.valve", "at most 15"},
      {file_with(avc_head + "{valve: 1, source_address: 0xFE, cycle: 20 ms}\n" + kPosition), 5,
       "joints[0].valve.iso11783_avc.source_address", "at most 253"},
      {file_with(avc_head + "{valve: 1, source_address: 0x8G, cycle: 20 ms}\n" + kPosition), 5,
       "joints[0].valve.iso11783_avc.source_address", "non-negative integer"},
      {file_with(avc_head + "{valve: 1, source_address: 0x80, cycle: 200 ms}\n" + kPosition), 5,
       "joints[0].valve.iso11783_avc.cycle", "between 1 ms and 100 ms"},
      {file_with(avc_head + "{valve: 1, source_address: 0x80, cycle: 20 bar}\n" + kPosition), 5,
       "joints[0].valve.iso11783_avc.cycle", "bar"},
      {file_with(avc_head + "{valve: 1, source_address: 0x80, cycle: 20 ms, fail_safe: open}\n" +
                 kPosition),
       5, "joints[0].valve.iso11783_avc.fail_safe", "block or float"},
      {file_with(avc_head + "{valve: 1, source_address: 0x80, cycl: 20 ms}\n" + kPosition), 5,
       "joints[0].valve.iso11783_avc.cycl", "unknown field"},
      {file_with("    valve: {}\n" + kPosition), 4, "joints[0].valve", "exactly one of"},
      {file_with(kValve +
                 "    position: {id: 0x18FF1021, start_bit: 0, length: 16, byte_order: intel,\n"
                 "               scale: 0.01, unit: deg}\n"),
       6, "joints[0].position.id", "at most 2047"},
      {file_with(kValve +
                 "    position: {id: 0x101, start_bit: 60, length: 16, byte_order: intel,\n"
                 "               scale: 0.01, unit: deg}\n"),
       6, "joints[0].position.start_bit", "runs past the 8th data byte"},
      {file_with(kValve +
                 "    position: {id: 0x101, start_bit: 6, length: 64, byte_order: motorola,\n"
                 "               scale: 0.01, unit: deg}\n"),
       6, "joints[0].position.start_bit", "runs past"},
      {file_with(kValve + "    position: {id: 0x101, start_bit: 0, length: 0, byte_order: intel,\n"
                          "               scale: 0.01, unit: deg}\n"),
       6, "joints[0].position.length", "1..64"},
      {file_with(kValve + "    position: {id: 0x101, start_bit: 0, length: 16, byte_order: pdp,\n"
                          "               scale: 0.01, unit: deg}\n"),
       6, "joints[0].position.byte_order", "intel"},
      {file_with(kValve + "    position: {id: 0x101, start_bit: 0, length: 16, byte_order: intel,\n"
                          "               scale: 0.01, unit: bar}\n"),
       7, "joints[0].position.unit", "not an angle"},
      {file_with(kValve + "    position: {id: 0x101, start_bit: 0, length: 16, byte_order: intel,\n"
                          "               scale: 0, unit: deg}\n"),
       7, "joints[0].position.scale", "nonzero"},
      {file_with(kValve + "    position: {id: 0x101, start_bit: 0, length: 16, byte_order: intel,\n"
                          "               scale: abc, unit: deg}\n"),
       7, "joints[0].position.scale", "not a number"},
      {file_with(kValve + "    position: {id: 0x101, start_bit: 0, length: 16, byte_order: intel,\n"
                          "               scale: 0.1, unit: deg, min: 5, max: 1}\n"),
       7, "joints[0].position.min", "at most max"},
      {file_with(kValve + kPosition +
                 "    pressure_a: {id: 0x301, start_bit: 0, length: 16, byte_order: intel,\n"
                 "                 scale: 0.01, unit: deg}\n"),
       9, "joints[0].pressure_a.unit", "not a pressure"},
      {file_with(kValve + kPosition +
                 "    pressure_a: {id: 0x18FF1021, extended: true, start_bit: 8, length: 16,\n"
                 "                 byte_order: intel, scale: 0.01, unit: bar}\n"),
       8, "joints[0].pressure_a", "overlaps the bits of joints[0].position"},
      {file_with(kValve + kPosition) + "  - name: slew\n" + kValve + kPosition, 8, "joints[1].name",
       "duplicate joint"},
      {file_with(kValve + kPosition) + "  - name: lift\n" + kValve + kPosition, 10,
       "joints[1].valve.iso11783_avc.valve", "already used by joint 'slew'"},
      {file_with("    valve:\n"
                 "      signal: {id: 0x210, start_bit: 0, length: 16, byte_order: intel,\n"
                 "               signed: true, scale: 1, unit: deg, cycle: 20 ms}\n" +
                 kPosition),
       6, "joints[0].valve.signal.unit", "current"},
      {file_with("    valve:\n"
                 "      signal: {id: 0x210, start_bit: 0, length: 16, byte_order: intel,\n"
                 "               signed: true, scale: 1, unit: mA}\n" +
                 kPosition),
       5, "joints[0].valve.signal.cycle", "missing"},
      {file_with("    valve:\n"
                 "      signal: {id: 0x18FF1021, extended: true, start_bit: 32, length: 16,\n"
                 "               byte_order: intel, scale: 1, unit: mA, cycle: 20 ms}\n" +
                 kPosition),
       7, "joints[0].position", "other direction"},
      {"format: craneassist-can-map/1\njoints: [\n", 3, "", "YAML syntax"},
      // A repeated key (yaml-cpp keeps both, a lookup takes the first): at the second.
      {file_with(kValve + "    position: {id: 0x101, start_bit: 0, length: 16, byte_order: intel,\n"
                          "               scale: 0.01, unit: deg, scale: 1}\n"),
       7, "joints[0].position.scale", "duplicate key (first at line 7)"},
      {"format: craneassist-can-map/1\nformat: craneassist-can-map/1\njoints: []\n", 2, "format",
       "duplicate key (first at line 1)"},
  };
  for (const Case& c : cases) {
    const ConfigError e = error_of(c.text);
    EXPECT_EQ(e.file(), "map.yaml");
    EXPECT_EQ(e.line(), c.line) << e.what();
    EXPECT_EQ(e.field(), c.field) << e.what();
    EXPECT_NE(e.reason().find(c.reason_part), std::string::npos) << e.what();
  }
}

TEST(CanMapping, Heartbeat) {
  const CanMapping shipped = load_can_mapping(kExample);
  ASSERT_TRUE(shipped.heartbeat.has_value());
  EXPECT_EQ(shipped.heartbeat->id, 0x18FF0080u);
  EXPECT_TRUE(shipped.heartbeat->extended);
  EXPECT_DOUBLE_EQ(shipped.heartbeat->cycle_s, 0.02);
  EXPECT_DOUBLE_EQ(shipped.heartbeat->timeout_s, 0.1);
  EXPECT_FALSE(parse_can_mapping(file_with(kValve + kPosition), "m.yaml").heartbeat.has_value());

  const std::string head = "format: craneassist-can-map/1\nheartbeat: ";
  const std::string joints = "\njoints:\n  - name: slew\n" + kValve + kPosition;
  struct Case {
    std::string heartbeat;
    std::string field;
    std::string reason_part;
  };
  const Case cases[] = {
      {"{id: 0x18FF0080, cycle: 20 ms, timeout: 30 ms}", "heartbeat.timeout", "two cycles"},
      {"{id: 0x18FF0080, cycle: 0 ms, timeout: 100 ms}", "heartbeat.cycle", "between 1 ms"},
      {"{id: 0x18FF0080, cycle: 20 ms}", "heartbeat.timeout", "missing"},
      {"{id: 0x800, extended: false, cycle: 20 ms, timeout: 100 ms}", "heartbeat.id",
       "at most 2047"},
      {"{id: 0x18FF0080, cycle: 20 ms, timeout: 100 ms, rate: 3}", "heartbeat.rate",
       "unknown field"},
      // The slew encoder's identifier: a received frame cannot also be sent.
      {"{id: 0x18FF1021, cycle: 20 ms, timeout: 100 ms}", "heartbeat", "other direction"},
      // The slew valve's AVC identifier (PGN 65072 from 0x80, priority 3).
      {"{id: 0x0CFE3080, cycle: 20 ms, timeout: 100 ms}", "heartbeat.id", "valve command"},
  };
  for (const auto& c : cases) {
    const ConfigError e = error_of(head + c.heartbeat + joints);
    EXPECT_EQ(e.field(), c.field) << c.heartbeat;
    EXPECT_NE(std::string(e.what()).find(c.reason_part), std::string::npos)
        << c.heartbeat << ": " << e.what();
    EXPECT_EQ(e.line(), 2) << c.heartbeat;
  }
}

TEST(CanMapping, PumpSignals) {
  const CanMapping m = load_can_mapping(kExample);
  ASSERT_TRUE(m.pump.pressure.has_value());
  ASSERT_TRUE(m.pump.flow.has_value());
  EXPECT_NEAR(m.pump.pressure->scale, 0.01 * 1e5, 1e-9);       // 0.01 bar/bit in Pa
  EXPECT_NEAR(m.pump.flow->scale, 0.01 * 1e-3 / 60.0, 1e-15);  // 0.01 L/min/bit in m^3/s
  const std::string joints = "joints:\n  - name: slew\n" + kValve + kPosition;
  auto e = error_of(
      "format: craneassist-can-map/1\npump:\n  flow: {id: 0x310, start_bit: 0, "
      "length: 16, byte_order: intel, scale: 1, unit: bar}\n" +
      joints);
  EXPECT_EQ(e.field(), "pump.flow.unit");
  EXPECT_NE(std::string(e.what()).find("volume flow"), std::string::npos) << e.what();
  e = error_of("format: craneassist-can-map/1\npump: {speed: 1}\n" + joints);
  EXPECT_EQ(e.field(), "pump.speed");
  // Sharing the slew encoder's frame is fine on free bits, not on the encoder's.
  e = error_of(
      "format: craneassist-can-map/1\npump:\n  pressure: {id: 0x18FF1021, extended: "
      "true, start_bit: 8, length: 16, byte_order: intel, scale: 1, unit: bar}\n" +
      joints);
  EXPECT_EQ(e.field(), "pump.pressure");
  EXPECT_NE(std::string(e.what()).find("overlaps"), std::string::npos) << e.what();
}

TEST(CanMapping, SwingSensorSignals) {
  const CanMapping m = load_can_mapping(kExample);
  ASSERT_TRUE(m.grapple.swing_radial.has_value());
  ASSERT_TRUE(m.grapple.swing_tangential.has_value());
  EXPECT_NEAR(m.grapple.swing_radial->scale, 0.01 * M_PI / 180.0, 1e-15);  // 0.01 deg/bit in rad
  EXPECT_TRUE(m.grapple.swing_tangential->is_signed);
  const std::string joints = "joints:\n  - name: slew\n" + kValve + kPosition;
  const std::string radial =
      "  swing_radial: {id: 0x320, start_bit: 0, length: 16, byte_order: intel, signed: true, "
      "scale: 0.01, unit: deg}\n";
  // Both axes or none: a two-axis sensor.
  auto e = error_of("format: craneassist-can-map/1\ngrapple:\n" + radial + joints);
  EXPECT_EQ(e.field(), "grapple.swing_tangential");
  e = error_of(
      "format: craneassist-can-map/1\ngrapple:\n  swing_radial: {id: 0x320, start_bit: 0, "
      "length: 16, byte_order: intel, scale: 1, unit: mm}\n" +
      joints);
  EXPECT_EQ(e.field(), "grapple.swing_radial.unit");
  EXPECT_NE(std::string(e.what()).find("an angle"), std::string::npos) << e.what();
  e = error_of("format: craneassist-can-map/1\ngrapple:\n" + radial +
               "  swing_tangential: {id: 0x320, start_bit: 8, length: 16, byte_order: intel, "
               "signed: true, scale: 0.01, unit: deg}\n" +
               joints);
  EXPECT_EQ(e.field(), "grapple.swing_tangential");
  EXPECT_NE(std::string(e.what()).find("overlaps"), std::string::npos) << e.what();
  e = error_of("format: craneassist-can-map/1\ngrapple: {swing: 1}\n" + joints);
  EXPECT_EQ(e.field(), "grapple.swing");
}

TEST(CanMapping, IsobusValveGroupExampleLoads) {
  const CanMapping m = load_can_mapping(std::string(CRANEASSIST_SOURCE_DIR) +
                                        "/config/can/pvg32_isobus_example.yaml");
  ASSERT_EQ(m.joints.size(), 4u);
  const char* names[] = {"slew", "lift", "tilt", "extension"};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(m.joints[i].name, names[i]);
    ASSERT_EQ(m.joints[i].valve.kind, ValveOutputKind::kIso11783Avc);
    EXPECT_EQ(m.joints[i].valve.avc.valve, i + 1);  // valve 0 is power beyond
    EXPECT_EQ(m.joints[i].valve.avc.fail_safe, iso11783::FailSafeMode::kBlock);
  }
  EXPECT_FALSE(m.joints[0].pressure_a.has_value());
  ASSERT_TRUE(m.heartbeat.has_value());
}

TEST(CanMapping, MissingFile) {
  try {
    load_can_mapping("/nonexistent/map.yaml");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(std::string(e.what()), "/nonexistent/map.yaml: file not found");
  }
}

// address_claim, valve.reply and diagnostics: values, and every mistake named by line and field.
TEST(CanMapping, AddressClaimRepliesAndDm1) {
  const std::string claim =
      "address_claim:\n"
      "  address: 0x80\n"
      "  name: {identity_number: 0xC1A, manufacturer_code: 0x7FE, function: 130,\n"
      "         industry_group: 3, function_instance: 2}\n"
      "diagnostics:\n"
      "  dm1: {source_addresses: [0x20, 0x21]}\n";
  const std::string signal_valve =
      "    valve:\n"
      "      signal: {id: 0x210, start_bit: 0, length: 16, byte_order: intel, signed: true,\n"
      "               scale: 1, unit: mA, min: -800, max: 800, cycle: 20 ms}\n"
      "      reply:\n"
      "        status: {id: 0x211, start_bit: 0, length: 8, byte_order: intel, ok: [0, 1]}\n"
      "        timeout: 250 ms\n";
  const std::string text =
      "format: craneassist-can-map/1\n" + claim +
      "joints:\n"
      "  - name: slew\n"
      "    valve:\n"
      "      iso11783_avc: {valve: 1, source_address: 0x80, cycle: 20 ms}\n"
      "      reply: {source_address: 0x20, timeout: 300 ms}\n" +
      kPosition + "  - name: lift\n" + signal_valve +
      "    position: {id: 0x18FF1022, extended: true, start_bit: 0,\n"
      "               length: 16, byte_order: intel, scale: 0.01, unit: deg}\n";
  const CanMapping m = parse_can_mapping(text, "map.yaml");
  ASSERT_TRUE(m.address_claim.has_value());
  EXPECT_EQ(m.address_claim->address, 0x80);
  EXPECT_DOUBLE_EQ(m.address_claim->timeout_s, 0.25);  // J1939-81's default
  const std::uint64_t name = m.address_claim->name;
  EXPECT_EQ(name & 0x1FFFFF, 0xC1Au);
  EXPECT_EQ((name >> 21) & 0x7FF, 0x7FEu);
  EXPECT_EQ((name >> 35) & 0x1F, 2u);
  EXPECT_EQ((name >> 40) & 0xFF, 130u);
  EXPECT_EQ((name >> 60) & 0x7, 3u);
  EXPECT_EQ(name >> 63, 0u);
  ASSERT_TRUE(m.dm1.has_value());
  EXPECT_EQ(m.dm1->source_addresses, (std::vector<std::uint8_t>{0x20, 0x21}));
  ASSERT_TRUE(m.joints[0].reply.has_value());
  EXPECT_EQ(m.joints[0].reply->source_address, 0x20);
  EXPECT_DOUBLE_EQ(m.joints[0].reply->timeout_s, 0.3);
  ASSERT_TRUE(m.joints[1].reply.has_value());
  EXPECT_EQ(m.joints[1].reply->status.id, 0x211u);
  EXPECT_EQ(m.joints[1].reply->status.length, 8);
  EXPECT_EQ(m.joints[1].reply->ok_values, (std::vector<std::uint64_t>{0, 1}));
  EXPECT_DOUBLE_EQ(m.joints[1].reply->timeout_s, 0.25);
  // The NAME as one 64-bit number; a single ok value.
  std::string hex_name = text;
  hex_name.replace(hex_name.find("{identity_number"),
                   hex_name.find("function_instance: 2}") + 21 - hex_name.find("{identity_number"),
                   "0x30820FFC00000C1A");
  EXPECT_EQ(parse_can_mapping(hex_name, "map.yaml").address_claim->name, 0x30820FFC00000C1Aull);

  struct Case {
    std::string from, to;
    std::string field, reason_part;
  };
  const Case cases[] = {
      {"address: 0x80", "address: 0xFE", "address_claim.address", "at most 253"},
      {"address: 0x80", "address: 0x81", "joints[0].valve.iso11783_avc.source_address",
       "is 0x80, the address_claim address is 0x81"},
      {"industry_group: 3,", "industry_group: 8,", "address_claim.name.industry_group",
       "at most 7"},
      {"manufacturer_code: 0x7FE,", "", "address_claim.name.manufacturer_code", "missing"},
      {"function_instance: 2}", "function_instance: 2, arbitrary_address_capable: true}",
       "address_claim.name.arbitrary_address_capable", "must be false"},
      {"function_instance: 2}", "ecu: 1}", "address_claim.name.ecu", "unknown field"},
      {"  dm1: {source_addresses: [0x20, 0x21]}", "  dm1: {source_addresses: [0x20, 0x20]}",
       "diagnostics.dm1.source_addresses[1]", "listed twice"},
      {"  dm1: {source_addresses: [0x20, 0x21]}", "  dm1: {source_addresses: [0x20, 0x80]}",
       "diagnostics.dm1.source_addresses[1]", "craneassist's own"},
      {"  dm1: {source_addresses: [0x20, 0x21]}", "  dm1: {source_addresses: []}",
       "diagnostics.dm1.source_addresses", "list of addresses"},
      {"  dm1: {source_addresses: [0x20, 0x21]}", "  dm2: {}", "diagnostics.dm2", "unknown field"},
      {"reply: {source_address: 0x20, timeout: 300 ms}",
       "reply: {source_address: 0x80, timeout: 300 ms}", "joints[0].valve.reply.source_address",
       "the command's source address"},
      {"reply: {source_address: 0x20, timeout: 300 ms}", "reply: {source_address: 0x20}",
       "joints[0].valve.reply.timeout", "missing"},
      {"reply: {source_address: 0x20, timeout: 300 ms}",
       "reply: {source_address: 0x20, timeout: 10 s}", "joints[0].valve.reply.timeout",
       "between 20 ms and 5 s"},
      {"reply: {source_address: 0x20, timeout: 300 ms}",
       "reply: {status: {id: 0x211}, timeout: 300 ms}", "joints[0].valve.reply.status",
       "unknown field"},
      {"ok: [0, 1]", "ok: [0, 256]", "joints[1].valve.reply.status.ok[1]", "at most 255"},
      {"ok: [0, 1]", "ok: []", "joints[1].valve.reply.status.ok", "at least one"},
      {"ok: [0, 1]", "ok: 0, scale: 2", "joints[1].valve.reply.status.scale", "unknown field"},
      // The status frame is received: it cannot also be the (sent) command's identifier.
      {"status: {id: 0x211,", "status: {id: 0x210, extended: false,",
       "joints[1].valve.reply.status", "other direction"},
      {"timeout: 250 ms\n", "timeout: 250 ms\n      valve: 3\n", "joints[1].valve.valve",
       "unknown field"},
  };
  for (const auto& c : cases) {
    std::string edited = text;
    const auto at = edited.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    edited.replace(at, c.from.size(), c.to);
    const ConfigError e = error_of(edited);
    EXPECT_EQ(e.field(), c.field) << e.what();
    EXPECT_NE(e.reason().find(c.reason_part), std::string::npos) << e.what();
    EXPECT_GT(e.line(), 0) << e.what();
  }
  // A J1939 heartbeat must come from the claimed address; an 11-bit one may be anything.
  auto e = error_of(
      "format: craneassist-can-map/1\nheartbeat: {id: 0x18FF0081, cycle: 20 ms, "
      "timeout: 100 ms}\n" +
      claim + "joints:\n  - name: slew\n" + kValve + kPosition);
  EXPECT_EQ(e.field(), "heartbeat.id");
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(e.reason().find("has source address 0x81 (its low byte), the address_claim address "
                            "is 0x80"),
            std::string::npos)
      << e.what();
  EXPECT_NO_THROW(
      parse_can_mapping("format: craneassist-can-map/1\nheartbeat: {id: 0x181, "
                        "extended: false, cycle: 20 ms, timeout: 100 ms}\n" +
                            claim + "joints:\n  - name: slew\n" + kValve + kPosition,
                        "map.yaml"));
  // The line of a wrong source address is the joint's valve line.
  e = error_of("format: craneassist-can-map/1\n" + claim + "joints:\n  - name: slew\n" +
               "    valve:\n      iso11783_avc: {valve: 0, source_address: 0x81, cycle: 20 ms}\n" +
               kPosition);
  EXPECT_EQ(e.line(), 11);
  EXPECT_EQ(e.field(), "joints[0].valve.iso11783_avc.source_address");
}
