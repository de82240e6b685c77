// DBC files: a mapping written as a DBC and read back through a mapping that names the DBC's
// signals is the same mapping; a DBC in the style of a machine maker's (comments, value tables,
// attributes, multiplexing, floats) loads; every mistake names the file, line and field.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "craneassist/can/dbc.hpp"
#include "craneassist/can/mapping_config.hpp"
#include "craneassist/config/config_error.hpp"
#include "thrown_error.hpp"

using namespace craneassist::can;
using craneassist::config::ConfigError;

namespace {

const std::string kConfigDir = std::string(CRANEASSIST_SOURCE_DIR) + "/config/can/";

void expect_same(const SignalSpec& a, const SignalSpec& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.extended, b.extended);
  EXPECT_EQ(a.start_bit, b.start_bit);
  EXPECT_EQ(a.length, b.length);
  EXPECT_EQ(a.byte_order, b.byte_order);
  EXPECT_EQ(a.is_signed, b.is_signed);
  // The DBC holds 15 significant digits of the file's numbers: equal to 1e-14 relative.
  EXPECT_NEAR(a.scale, b.scale, 1e-14 * std::abs(b.scale));
  EXPECT_NEAR(a.offset, b.offset, 1e-14 * std::abs(b.offset) + 1e-300);
  ASSERT_EQ(a.minimum.has_value(), b.minimum.has_value());
  ASSERT_EQ(a.maximum.has_value(), b.maximum.has_value());
  if (a.minimum) {
    EXPECT_NEAR(*a.minimum, *b.minimum, 1e-12 * (1.0 + std::abs(*b.minimum)));
  }
  if (a.maximum) {
    EXPECT_NEAR(*a.maximum, *b.maximum, 1e-12 * (1.0 + std::abs(*b.maximum)));
  }
  EXPECT_EQ(a.unit, b.unit);
  EXPECT_DOUBLE_EQ(a.unit_si, b.unit_si);
}

void expect_same(const CanMapping& a, const CanMapping& b) {
  ASSERT_EQ(a.joints.size(), b.joints.size());
  for (std::size_t i = 0; i < a.joints.size(); ++i) {
    const JointMapping& x = a.joints[i];
    const JointMapping& y = b.joints[i];
    EXPECT_EQ(x.name, y.name);
    ASSERT_EQ(x.valve.kind, y.valve.kind);
    if (x.valve.kind == ValveOutputKind::kSignal) {
      expect_same(x.valve.signal.signal, y.valve.signal.signal, x.name + ".valve");
      EXPECT_DOUBLE_EQ(x.valve.signal.cycle_s, y.valve.signal.cycle_s);
    }
    expect_same(x.position, y.position, x.name + ".position");
    EXPECT_EQ(x.position_kind, y.position_kind);
    ASSERT_EQ(x.pressure_a.has_value(), y.pressure_a.has_value());
    ASSERT_EQ(x.pressure_b.has_value(), y.pressure_b.has_value());
    if (x.pressure_a) expect_same(*x.pressure_a, *y.pressure_a, x.name + ".pressure_a");
    if (x.pressure_b) expect_same(*x.pressure_b, *y.pressure_b, x.name + ".pressure_b");
  }
  ASSERT_EQ(a.heartbeat.has_value(), b.heartbeat.has_value());
  if (a.heartbeat) {
    EXPECT_EQ(a.heartbeat->id, b.heartbeat->id);
    EXPECT_EQ(a.heartbeat->extended, b.heartbeat->extended);
    EXPECT_DOUBLE_EQ(a.heartbeat->cycle_s, b.heartbeat->cycle_s);
    EXPECT_DOUBLE_EQ(a.heartbeat->timeout_s, b.heartbeat->timeout_s);
  }
  ASSERT_EQ(a.pump.pressure.has_value(), b.pump.pressure.has_value());
  ASSERT_EQ(a.pump.flow.has_value(), b.pump.flow.has_value());
  if (a.pump.pressure) expect_same(*a.pump.pressure, *b.pump.pressure, "pump.pressure");
  if (a.pump.flow) expect_same(*a.pump.flow, *b.pump.flow, "pump.flow");
  ASSERT_EQ(a.grapple.swing_radial.has_value(), b.grapple.swing_radial.has_value());
  ASSERT_EQ(a.grapple.swing_tangential.has_value(), b.grapple.swing_tangential.has_value());
  if (a.grapple.swing_radial) {
    expect_same(*a.grapple.swing_radial, *b.grapple.swing_radial, "grapple.swing_radial");
    expect_same(*a.grapple.swing_tangential, *b.grapple.swing_tangential,
                "grapple.swing_tangential");
  }
}

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A DBC in the style of a machine maker's export: a version, the NS_ list, a baud rate, node
// and value tables, comments over several lines with quotes, attribute definitions, a
// multiplexed message, a float signal, transmitters, // comments.
const char* const kVendorDbc = R"(VERSION "1.2.3"


NS_ :
	NS_DESC_
	CM_
	BA_DEF_
	BA_
	VAL_
	CAT_DEF_
	SIG_VALTYPE_

BS_: 250000 : 0,0

BU_: ECU1 Valves Display
VAL_TABLE_ OnOff 1 "on" 0 "off" ;

// Boom sensors
BO_ 2566848513 BoomAngles: 8 ECU1
 SG_ Boom1Angle : 0|16@1- (0.01,-10) [-190|170] "deg" Valves,Display
 SG_ Boom2Angle : 16|16@1- (0.01,0) [0|0] "°" Valves
 SG_ ArmAngle : 39|16@0+ (0.1,0) [0|3600] "deg"  Display

BO_ 1280 Muxed: 8 ECU1
 SG_ Selector M : 0|8@1+ (1,0) [0|3] "" Display
 SG_ PressureA m0 : 8|16@1+ (0.1,0) [0|500] "bar" Display
 SG_ Temperature : 24|32@1- (1,0) [0|0] "degC" Display

BO_ 2147484416 TelescopeCmd: 4 Display
 SG_ TelescopeCurrent : 0|16@1- (1,0) [-1000|1000] "mA" Valves
 SG_ Gain : 16|16@1+ (1,0) [0|0] "" Valves

BO_TX_BU_ 1280 : ECU1,Display;

CM_ "A vendor ""DBC"" for tests";
CM_ BO_ 2566848513 "Boom angles, from the
inclinometers; two lines";
CM_ SG_ 2566848513 Boom1Angle "zero at horizontal";
BA_DEF_ BO_  "GenMsgCycleTime" INT 0 10000;
BA_DEF_ BO_  "VFrameFormat" ENUM  "StandardCAN","ExtendedCAN","reserved","J1939PG";
BA_DEF_ SG_  "SPN" INT 0 524287;
BA_DEF_DEF_  "GenMsgCycleTime" 0;
BA_ "GenMsgCycleTime" BO_ 2566848513 10;
BA_ "VFrameFormat" BO_ 2566848513 3;
BA_ "GenMsgCycleTime" BO_ 2147484416 20;
BA_ "SPN" SG_ 2566848513 Boom1Angle 520192;
VAL_ 1280 Selector 0 "pressures" 1 "temperatures" ;
SIG_VALTYPE_ 1280 Temperature : 1;
)";

}  // namespace

TEST(CanDbc, ShippedDbcIsWhatCanDbcWritesForTheK70mMapping) {
  // config/can/k70m.dbc is `craneassist can dbc` of k70m_can.yaml: regenerate it when the
  // mapping or the writer changes.
  const CanMapping mapping = load_can_mapping(kConfigDir + "k70m_can.yaml");
  EXPECT_EQ(write_dbc(mapping, "k70m_can.yaml"), read(kConfigDir + "k70m.dbc"))
      << "regenerate: craneassist can dbc --mapping config/can/k70m_can.yaml -o "
         "config/can/k70m.dbc";
}

TEST(CanDbc, MappingThatNamesTheDbcsSignalsIsTheSameMapping) {
  const CanMapping spelled = load_can_mapping(kConfigDir + "k70m_can.yaml");
  const CanMapping from_dbc = load_can_mapping(kConfigDir + "k70m_from_dbc.yaml");
  expect_same(from_dbc, spelled);
}

TEST(CanDbc, RoundTripOfEveryShippedMapping) {
  for (const char* name : {"k70m_can.yaml", "pvg32_isobus_example.yaml"}) {
    SCOPED_TRACE(name);
    const CanMapping mapping = load_can_mapping(kConfigDir + name);
    const Dbc dbc = parse_dbc(write_dbc(mapping, name), "written.dbc");
    // Every mapping signal is in the DBC, at the same place with the same scaling.
    std::size_t signals = 0;
    const auto find = [&](const std::string& message, const std::string& signal) {
      const DbcMessage* m = dbc.message(message);
      EXPECT_NE(m, nullptr) << message;
      if (m == nullptr) return SignalSpec{};
      for (const auto& s : m->signals) {
        if (s.name == signal) {
          ++signals;
          return s.spec;
        }
      }
      ADD_FAILURE() << message << "." << signal;
      return SignalSpec{};
    };
    for (const auto& j : mapping.joints) {
      const SignalSpec p = find(j.name + "_position", j.name + "_position");
      EXPECT_EQ(p.id, j.position.id);
      EXPECT_EQ(p.start_bit, j.position.start_bit);
      EXPECT_EQ(p.byte_order, j.position.byte_order);
      EXPECT_NEAR(p.scale * j.position.unit_si, j.position.scale, 1e-15);
      EXPECT_EQ(p.unit, j.position.unit);
      if (j.valve.kind == ValveOutputKind::kIso11783Avc) {
        const DbcMessage* m = dbc.message("AuxValveCommand" + std::to_string(j.valve.avc.valve));
        ASSERT_NE(m, nullptr);
        EXPECT_TRUE(m->j1939);
        EXPECT_TRUE(m->extended);
        EXPECT_EQ(m->dlc, 8);
        EXPECT_EQ(m->id & 0xFFu, j.valve.avc.source_address);
        ASSERT_TRUE(m->cycle_s.has_value());
        EXPECT_DOUBLE_EQ(*m->cycle_s, j.valve.avc.cycle_s);
        EXPECT_EQ(m->sender, "craneassist");
      }
    }
    EXPECT_EQ(signals, mapping.joints.size());
  }
}

TEST(CanDbc, TheClaimTheValveRepliesAndDm1AreInTheDbc) {
  const CanMapping mapping = load_can_mapping(kConfigDir + "k70m_can.yaml");
  ASSERT_TRUE(mapping.address_claim.has_value());
  const Dbc dbc = parse_dbc(write_dbc(mapping, "k70m_can.yaml"), "written.dbc");
  // craneassist's claim: PGN 60928 from its address, the NAME's fields in their bits.
  const DbcMessage* claim = dbc.message("AddressClaimed_80");
  ASSERT_NE(claim, nullptr);
  EXPECT_EQ(claim->id, 0x18EEFF80u);
  EXPECT_EQ(claim->sender, "craneassist");
  ASSERT_EQ(claim->signals.size(), 10u);
  CanFrame frame;
  frame.id = claim->id;
  frame.extended = true;
  frame.dlc = 8;
  for (int i = 0; i < 8; ++i) {
    frame.data[static_cast<std::size_t>(i)] =
        static_cast<std::uint8_t>(mapping.address_claim->name >> (8 * i));
  }
  const auto field = [&](const DbcMessage& m, const char* name) {
    for (const auto& s : m.signals) {
      if (s.name == name) {
        double v = -1.0;
        EXPECT_EQ(decode(s.spec, frame, v), SignalStatus::kOk) << name;
        return v;
      }
    }
    ADD_FAILURE() << "no signal " << name;
    return -1.0;
  };
  EXPECT_EQ(field(*claim, "IdentityNumber"), 0xC1A);  // config/can/k70m_can.yaml's NAME
  EXPECT_EQ(field(*claim, "Function"), 130);
  EXPECT_EQ(field(*claim, "IndustryGroup"), 3);
  EXPECT_EQ(field(*claim, "ArbitraryAddressCapable"), 0);
  // The valve group at 0x20: its claim, the Estimated Flow of every supervised valve, DM1.
  ASSERT_NE(dbc.message("AddressClaimed_20"), nullptr);
  for (int valve = 0; valve < 3; ++valve) {
    const DbcMessage* ef = dbc.message("AuxValveEstimatedFlow" + std::to_string(valve));
    ASSERT_NE(ef, nullptr) << valve;
    EXPECT_EQ(ef->id, 0x0CFE1020u + (static_cast<std::uint32_t>(valve) << 8));
    EXPECT_EQ(ef->sender, "machine");
    EXPECT_TRUE(ef->j1939);
  }
  const DbcMessage* dm1 = dbc.message("DM1_20");
  ASSERT_NE(dm1, nullptr);
  EXPECT_EQ(dm1->id, 0x18FECA20u);
  ASSERT_TRUE(dm1->cycle_s.has_value());
  EXPECT_DOUBLE_EQ(*dm1->cycle_s, 1.0);
  // SPN 1234 FMI 5 with the red stop lamp, as craneassist's DM1 codec lays it out.
  frame.id = dm1->id;
  frame.data = {0x10, 0xFF, 0xD2, 0x04, 0x05, 0x01, 0xFF, 0xFF};
  EXPECT_EQ(field(*dm1, "RedStopLamp"), 1);
  EXPECT_EQ(field(*dm1, "SpnLow") + 65536 * field(*dm1, "SpnHigh"), 1234);
  EXPECT_EQ(field(*dm1, "Fmi"), 5);
  EXPECT_EQ(field(*dm1, "OccurrenceCount"), 1);
  // The extension driver's status byte, with its OK value named.
  const DbcMessage* status = dbc.message("extension_valve_status");
  ASSERT_NE(status, nullptr);
  EXPECT_EQ(status->id, 0x211u);
  EXPECT_EQ(status->sender, "machine");
}

TEST(CanDbc, ReadsAVendorStyleDbc) {
  const Dbc dbc = parse_dbc(kVendorDbc, "vendor.dbc");
  ASSERT_EQ(dbc.messages.size(), 3u);
  const DbcMessage* boom = dbc.message("BoomAngles");
  ASSERT_NE(boom, nullptr);
  EXPECT_EQ(boom->id, 0x18FF0001u);
  EXPECT_TRUE(boom->extended);
  EXPECT_TRUE(boom->j1939);
  EXPECT_EQ(boom->sender, "ECU1");
  ASSERT_TRUE(boom->cycle_s.has_value());
  EXPECT_DOUBLE_EQ(*boom->cycle_s, 0.01);
  ASSERT_EQ(boom->signals.size(), 3u);
  const SignalSpec& a = boom->signals[0].spec;
  EXPECT_EQ(a.start_bit, 0);
  EXPECT_EQ(a.length, 16);
  EXPECT_TRUE(a.is_signed);
  EXPECT_DOUBLE_EQ(a.scale, 0.01);
  EXPECT_DOUBLE_EQ(a.offset, -10.0);
  EXPECT_DOUBLE_EQ(*a.minimum, -190.0);
  EXPECT_DOUBLE_EQ(*a.maximum, 170.0);
  EXPECT_EQ(a.unit, "deg");
  EXPECT_FALSE(boom->signals[1].spec.minimum.has_value()) << "[0|0] is no range";
  EXPECT_EQ(boom->signals[1].spec.unit, "°");
  EXPECT_EQ(boom->signals[2].spec.byte_order, ByteOrder::kBigEndian);
  EXPECT_EQ(boom->signals[2].spec.start_bit, 39);

  const DbcMessage* muxed = dbc.message("Muxed");
  ASSERT_NE(muxed, nullptr);
  EXPECT_EQ(muxed->id, 1280u);
  EXPECT_FALSE(muxed->extended);
  EXPECT_TRUE(muxed->signals[0].multiplexed);
  EXPECT_TRUE(muxed->signals[1].multiplexed);
  EXPECT_EQ(muxed->signals[2].value_type, 1);

  const DbcMessage* cmd = dbc.message("TelescopeCmd");
  ASSERT_NE(cmd, nullptr);
  EXPECT_EQ(cmd->id, 0x300u);
  EXPECT_TRUE(cmd->extended) << "bit 31 marks a 29-bit identifier";
  EXPECT_EQ(cmd->dlc, 4);
}

TEST(CanDbc, MappingNamesVendorSignals) {
  const auto dir = std::filesystem::temp_directory_path() / "craneassist_test_can_dbc";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "vendor.dbc") << kVendorDbc;
  const auto mapping_with = [&](const std::string& position) {
    return "format: craneassist-can-map/1\n"
           "dbc: vendor.dbc\n"
           "joints:\n"
           "  - name: telescope\n"
           "    valve:\n"
           "      signal: {dbc: TelescopeCmd.TelescopeCurrent}\n"
           "    position: " +
           position + "\n";
  };
  const auto parse = [&](const std::string& position) {
    const std::string path = (dir / "map.yaml").string();
    std::ofstream(path) << mapping_with(position);
    return load_can_mapping(path);
  };
  const CanMapping m = parse("{dbc: BoomAngles.Boom1Angle}");
  ASSERT_EQ(m.joints.size(), 1u);
  EXPECT_NEAR(m.joints[0].position.scale, 0.01 * std::numbers::pi / 180.0, 1e-15);
  EXPECT_NEAR(m.joints[0].position.offset, -10.0 * std::numbers::pi / 180.0, 1e-15);
  EXPECT_DOUBLE_EQ(m.joints[0].valve.signal.cycle_s, 0.02) << "GenMsgCycleTime";
  EXPECT_NEAR(m.joints[0].valve.signal.signal.scale, 1e-3, 1e-18) << "mA in A";

  // A unit craneassist does not know needs `unit:`.
  const auto error = [&](const std::string& position) {
    return craneassist::test::thrown_error<ConfigError>([&] { parse(position); }, position);
  };
  const ConfigError degree = error("{dbc: BoomAngles.Boom2Angle}");
  EXPECT_EQ(degree.line(), 7);
  EXPECT_NE(degree.reason().find("unit '°' (" + (dir / "vendor.dbc").string() + ":21)"),
            std::string::npos)
      << degree.what();
  EXPECT_NE(degree.reason().find("give 'unit:'"), std::string::npos);
  EXPECT_NEAR(parse("{dbc: BoomAngles.Boom2Angle, unit: deg}").joints[0].position.scale,
              0.01 * std::numbers::pi / 180.0, 1e-15);

  const ConfigError no_message = error("{dbc: Boom.Boom1Angle}");
  EXPECT_EQ(no_message.field(), "joints[0].position.dbc");
  EXPECT_NE(no_message.reason().find("no message 'Boom'"), std::string::npos);
  EXPECT_NE(no_message.reason().find("BoomAngles, Muxed, TelescopeCmd"), std::string::npos);
  const ConfigError no_signal = error("{dbc: BoomAngles.Boom3Angle}");
  EXPECT_NE(no_signal.reason().find("has no signal 'Boom3Angle' (it has Boom1Angle, Boom2Angle, "
                                    "ArmAngle)"),
            std::string::npos)
      << no_signal.what();
  EXPECT_NE(error("{dbc: Muxed.PressureA}").reason().find("multiplexed"), std::string::npos);
  EXPECT_NE(error("{dbc: Muxed.Temperature}").reason().find("floating-point"), std::string::npos);
  EXPECT_NE(error("{dbc: BoomAngles}").reason().find("expected MESSAGE.SIGNAL"), std::string::npos);
  EXPECT_NE(error("{dbc: BoomAngles.ArmAngle, start_bit: 3}").reason().find("unknown field"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(CanDbc, ADbcReferenceNeedsTheDbc) {
  const std::string text =
      "format: craneassist-can-map/1\n"
      "joints:\n"
      "  - name: slew\n"
      "    valve: {iso11783_avc: {valve: 0, source_address: 0x80, cycle: 20 ms}}\n"
      "    position: {dbc: slew_position.slew_position}\n";
  const ConfigError e = craneassist::test::thrown_error<ConfigError>(
      [&] { parse_can_mapping(text, "map.yaml"); }, "no top-level dbc");
  EXPECT_EQ(e.line(), 5);
  EXPECT_NE(e.reason().find("no top-level 'dbc: FILE'"), std::string::npos);

  const ConfigError missing = craneassist::test::thrown_error<ConfigError>(
      [&] {
        parse_can_mapping("format: craneassist-can-map/1\ndbc: nowhere.dbc\n", "/x/map.yaml");
      },
      "a missing DBC");
  EXPECT_EQ(missing.file(), "/x/map.yaml");
  EXPECT_EQ(missing.line(), 2);
  EXPECT_NE(missing.reason().find("cannot read /x/nowhere.dbc: file not found"), std::string::npos)
      << missing.what();
}

TEST(CanDbc, ErrorsNameTheDbcLine) {
  const auto error = [](const std::string& text) {
    return craneassist::test::thrown_error<ConfigError>([&] { parse_dbc(text, "m.dbc"); }, text);
  };
  const ConfigError bad_order = error("BO_ 100 M: 8 X\n SG_ S : 0|8@2+ (1,0) [0|0] \"\" X\n");
  EXPECT_EQ(bad_order.file(), "m.dbc");
  EXPECT_EQ(bad_order.line(), 2);
  EXPECT_EQ(bad_order.field(), "SG_ S");
  EXPECT_NE(bad_order.reason().find("byte order"), std::string::npos);
  EXPECT_NE(
      error("BO_ 100 M: 8 X\n SG_ S : 60|8@1+ (1,0) [0|0] \"\" X\n").reason().find("runs past"),
      std::string::npos);
  EXPECT_NE(error("BO_ 100 M: 9 X\n").reason().find("at most 8"), std::string::npos);
  EXPECT_NE(error("BO_ 100 M: 8 X\n SG_ S : 0|8@1+ (0,0) [0|0] \"\" X\n").reason().find("nonzero"),
            std::string::npos);
  EXPECT_EQ(error("\n\nSG_ S : 0|8@1+ (1,0) [0|0] \"\" X\n").line(), 3);
  EXPECT_NE(error("CM_ \"open").reason().find("not closed"), std::string::npos);
  EXPECT_NE(error("CM_ \"no end\"").reason().find("no ';'"), std::string::npos);
  EXPECT_NE(error("BO_ 100 M: 8 X\n SG_ S : 0|8@1+ (1,0) [0|0] \"\" X\n"
                  " SG_ S : 8|8@1+ (1,0) [0|0] \"\" X\n")
                .reason()
                .find("a second signal"),
            std::string::npos);
  EXPECT_NE(error("BO_ 4294967295 M: 8 X\n").reason().find("above 29 bits"), std::string::npos);
  EXPECT_NE(error("BO_ 100 M: 8 X\n SG_ S : 0|8@1+ (1e999,0) [0|0] \"\" X\n")
                .reason()
                .find("not a number"),
            std::string::npos);
}
