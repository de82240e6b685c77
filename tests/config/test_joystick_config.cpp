// The joystick mapping file: the shipped default reads back as the built-in gamepad layout, and
// every mistake is reported with file, line and field.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

#include "craneassist/config/joystick_config.hpp"
#include "thrown_error.hpp"

using namespace craneassist;

namespace {

std::string default_text() {
  std::ifstream in(std::string(CRANEASSIST_SOURCE_DIR) + "/config/joysticks/gamepad.yaml");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The error after replacing `from` by `to` in the default file.
config::ConfigError error_after_edit(const std::string& from, const std::string& to) {
  std::string text = default_text();
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  text.replace(pos, from.size(), to);
  return test::thrown_error<config::ConfigError>(
      [&] { config::parse_joystick_config(text, "pad.yaml"); }, "no error for " + to);
}

}  // namespace

TEST(JoystickConfig, ShippedDefaultIsTheGamepadLayout) {
  const auto c = config::default_joystick_config();
  const auto d = input::default_gamepad_mapping();
  EXPECT_EQ(c.mapping.frame, input::MappingFrame::kCylindrical);
  EXPECT_EQ(c.mapping.deadman, input::GamepadButton::kRightShoulder);
  for (std::size_t i = 0; i < input::kOperatorAxisCount; ++i) {
    EXPECT_EQ(c.mapping.axes[i].axis, d.axes[i].axis) << i;
    EXPECT_EQ(c.mapping.axes[i].invert, d.axes[i].invert) << i;
    EXPECT_DOUBLE_EQ(c.mapping.axes[i].max, d.axes[i].max) << i;
    EXPECT_DOUBLE_EQ(c.mapping.axes[i].deadband, d.axes[i].deadband) << i;
    EXPECT_DOUBLE_EQ(c.mapping.axes[i].expo, d.axes[i].expo) << i;
  }
  EXPECT_DOUBLE_EQ(c.monitor.stale_timeout_s, 0.1);
  EXPECT_DOUBLE_EQ(c.monitor.max_speed_m_s, 2.0);
  EXPECT_DOUBLE_EQ(c.monitor.deadman_hold_s, 0.3);
  EXPECT_DOUBLE_EQ(c.monitor.stop_latch_s, 1.0);
  EXPECT_DOUBLE_EQ(c.keyboard.first_hold_s, 0.55);
  EXPECT_DOUBLE_EQ(c.keyboard.repeat_hold_s, 0.15);
}

TEST(JoystickConfig, AngularSlewAndCartesianFrame) {
  std::string text = default_text();
  text.replace(text.find("slew: tangential"), 16, "slew: angular");
  text.replace(text.find("max: 0.5 m/s"), 12, "max: 20 deg/s");
  text.replace(text.find("frame: cylindrical"), 18, "frame: cartesian");
  const auto c = config::parse_joystick_config(text, "pad.yaml");
  EXPECT_EQ(c.mapping.slew, input::SlewMode::kAngular);
  EXPECT_EQ(c.mapping.frame, input::MappingFrame::kCartesian);
  EXPECT_NEAR(c.mapping.axes[0].max, 20.0 * M_PI / 180.0, 1e-12);
}

// The deadman's timing rules: optional (a file without them gets the defaults), 0 turns them off,
// out of range or in the wrong unit is an error naming the field.
TEST(JoystickConfig, DeadmanHoldAndStopLatch) {
  std::string text = default_text();
  text.replace(text.find("deadman_hold: 300 ms"), 20, "deadman_hold: 0.5 s");
  text.replace(text.find("stop_latch: 1 s"), 15, "stop_latch: 0 s");
  auto c = config::parse_joystick_config(text, "pad.yaml");
  EXPECT_DOUBLE_EQ(c.monitor.deadman_hold_s, 0.5);
  EXPECT_DOUBLE_EQ(c.monitor.stop_latch_s, 0.0);

  text = default_text();
  for (const char* key : {"  deadman_hold:", "  stop_latch:"}) {
    const auto at = text.find(key);
    ASSERT_NE(at, std::string::npos) << key;
    text.erase(at, text.find('\n', at) - at + 1);
  }
  c = config::parse_joystick_config(text, "pad.yaml");
  EXPECT_DOUBLE_EQ(c.monitor.deadman_hold_s, input::InputMonitorSettings{}.deadman_hold_s);
  EXPECT_DOUBLE_EQ(c.monitor.stop_latch_s, input::InputMonitorSettings{}.stop_latch_s);

  auto e = error_after_edit("deadman_hold: 300 ms", "deadman_hold: 3 s");
  EXPECT_EQ(e.field(), "input.deadman_hold");
  EXPECT_EQ(e.reason(), "must be 0 to 2 s");
  e = error_after_edit("stop_latch: 1 s", "stop_latch: 1 m");
  EXPECT_EQ(e.field(), "input.stop_latch");
  EXPECT_NE(e.reason().find("not a time unit"), std::string::npos) << e.what();
}

TEST(JoystickConfig, ErrorsNameFileLineAndField) {
  auto e = error_after_edit("axis: left_y", "axis: left_z");
  EXPECT_EQ(e.file(), "pad.yaml");
  EXPECT_EQ(e.field(), "joystick.axes.radial.axis");
  EXPECT_EQ(e.line(), 28);
  EXPECT_NE(e.reason().find("unknown axis 'left_z'"), std::string::npos) << e.what();

  e = error_after_edit("deadman: right_shoulder", "deadman: right_shoe");
  EXPECT_EQ(e.field(), "joystick.deadman");
  EXPECT_EQ(e.line(), 16);

  e = error_after_edit("stale_timeout: 100 ms", "stale_timeout: 100 m");
  EXPECT_EQ(e.field(), "input.stale_timeout");
  EXPECT_EQ(e.line(), 8);
  EXPECT_NE(e.reason().find("not a time unit"), std::string::npos) << e.what();

  e = error_after_edit("deadband: 0.12", "deadband: 0.95");
  EXPECT_EQ(e.field(), "joystick.axes.lateral.deadband");
  EXPECT_EQ(e.reason(), "must be 0 to 0.9");

  e = error_after_edit("      expo: 0.4\n      max: 0.4 m/s",
                       "      expo: 0.4\n      maxx: 0.4 m/s");
  EXPECT_EQ(e.field(), "joystick.axes.vertical.maxx");
  EXPECT_NE(e.reason().find("unknown field"), std::string::npos);

  e = error_after_edit("invert: true", "invert: yes please");
  EXPECT_EQ(e.field(), "joystick.axes.radial.invert");

  e = error_after_edit("frame: cylindrical", "frame: polar");
  EXPECT_EQ(e.field(), "joystick.frame");

  e = error_after_edit("format: craneassist-joystick/1", "format: craneassist-crane/1");
  EXPECT_EQ(e.field(), "format");
  EXPECT_EQ(e.line(), 4);

  e = error_after_edit("first_hold: 550 ms", "first_hold: 5 s");
  EXPECT_EQ(e.field(), "keyboard.first_hold");

  // The angular slew wants an angular velocity.
  e = error_after_edit("slew: tangential", "slew: angular");
  EXPECT_EQ(e.field(), "joystick.axes.lateral.max");
  EXPECT_NE(e.reason().find("angular velocity"), std::string::npos) << e.what();
}

TEST(JoystickConfig, DriveStick) {
  // The shipped drive-mode mapping: the right stick drives, the left moves the tip.
  const auto c = config::load_joystick_config(std::string(CRANEASSIST_SOURCE_DIR) +
                                              "/config/joysticks/gamepad_drive.yaml");
  const auto& speed = c.mapping.drive[static_cast<std::size_t>(input::DriveAxis::kSpeed)];
  const auto& curv = c.mapping.drive[static_cast<std::size_t>(input::DriveAxis::kCurvature)];
  EXPECT_TRUE(speed.enabled);
  EXPECT_EQ(speed.axis, input::GamepadAxis::kRightY);
  EXPECT_TRUE(speed.invert);
  EXPECT_DOUBLE_EQ(speed.max, 1.0);
  EXPECT_EQ(curv.axis, input::GamepadAxis::kRightX);
  input::JoystickMapper mapper(c.mapping);
  input::GamepadState pad;
  pad.axes[static_cast<std::size_t>(input::GamepadAxis::kRightY)] = -1.0;  // forward
  pad.axes[static_cast<std::size_t>(input::GamepadAxis::kRightX)] = 1.0;   // right
  const Eigen::Vector2d d = mapper.drive(pad);
  EXPECT_DOUBLE_EQ(d[0], 1.0);
  EXPECT_DOUBLE_EQ(d[1], -1.0);
  // The default mapping has no drive stick.
  EXPECT_TRUE(input::JoystickMapper(config::default_joystick_config().mapping).drive(pad).isZero());
  // The drive mode's embedded mappings (sim --drive without --joystick): the gamepad's is the
  // file above; the web page's drives the same way with web.yaml's input rules.
  const auto embedded = config::drive_joystick_config();
  EXPECT_TRUE(input::JoystickMapper(embedded.mapping).drive(pad).isApprox(d));
  const auto web = config::web_drive_joystick_config();
  EXPECT_TRUE(input::JoystickMapper(web.mapping).drive(pad).isApprox(d));
  EXPECT_DOUBLE_EQ(web.monitor.stale_timeout_s,
                   config::web_joystick_config().monitor.stale_timeout_s);
  EXPECT_NE(web.source_name.find("web_drive.yaml"), std::string::npos);

  // A drive axis that a tip axis uses already, and one axis for both drive axes: errors.
  std::string text = default_text();
  const std::string drive =
      "  drive:\n    speed:\n      axis: right_y\n      deadband: 0.1\n      expo: 0\n"
      "    curvature:\n      axis: right_x\n      deadband: 0.1\n      expo: 0\n";
  const auto pos = text.find("\nkeyboard:");
  text.insert(pos + 1, drive);
  const auto e = test::thrown_error<config::ConfigError>(
      [&] { config::parse_joystick_config(text, "pad.yaml"); }, "no error");
  EXPECT_EQ(e.field(), "joystick.drive.speed.axis");
  EXPECT_NE(e.reason().find("joystick.axes.vertical"), std::string::npos) << e.what();
  std::string both = text;
  both.replace(both.find("axis: right_y\n      deadband: 0.1"), 13, "axis: left_trigger");
  both.replace(both.find("axis: right_x\n      deadband: 0.1"), 13, "axis: left_trigger");
  const auto e2 = test::thrown_error<config::ConfigError>(
      [&] { config::parse_joystick_config(both, "pad.yaml"); }, "no error");
  EXPECT_EQ(e2.field(), "joystick.drive.curvature.axis");
}

TEST(JoystickConfig, MissingFileAndYamlSyntax) {
  try {
    config::load_joystick_config("/nonexistent/pad.yaml");
    FAIL();
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.file(), "/nonexistent/pad.yaml");
    EXPECT_EQ(e.line(), 0);
  }
  try {
    config::parse_joystick_config("format: [\n", "x.yaml");
    FAIL();
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("YAML syntax"), std::string::npos);
  }
}

// A repeated key is an error at the second one (yaml-cpp keeps both, a lookup takes the first).
TEST(JoystickConfig, DuplicateKeysAreRejected) {
  const std::string text = default_text();
  const std::string line = "  max_speed: 2 m/s";
  const auto at = text.find(line);
  ASSERT_NE(at, std::string::npos);
  const int first = 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
  const auto e = error_after_edit(line, line + "\n  max_speed: 5 m/s");
  EXPECT_EQ(std::string(e.what()), "pad.yaml:" + std::to_string(first + 1) +
                                       ": field 'input.max_speed': duplicate key (first at line " +
                                       std::to_string(first) + ")");
}

TEST(JoystickConfig, TheWebPageMapsLikeTheGamepadWithALongerStaleTimeout) {
  const auto pad = config::default_joystick_config();
  const auto web = config::web_joystick_config();
  EXPECT_DOUBLE_EQ(web.monitor.stale_timeout_s, 0.25);
  EXPECT_DOUBLE_EQ(pad.monitor.stale_timeout_s, 0.1);
  EXPECT_DOUBLE_EQ(web.monitor.deadman_hold_s, pad.monitor.deadman_hold_s);
  EXPECT_DOUBLE_EQ(web.monitor.stop_latch_s, pad.monitor.stop_latch_s);
  EXPECT_EQ(web.mapping.deadman, pad.mapping.deadman);
  EXPECT_EQ(web.mapping.frame, pad.mapping.frame);
  for (std::size_t i = 0; i < input::kOperatorAxisCount; ++i) {
    EXPECT_EQ(web.mapping.axes[i].axis, pad.mapping.axes[i].axis);
    EXPECT_EQ(web.mapping.axes[i].invert, pad.mapping.axes[i].invert);
    EXPECT_DOUBLE_EQ(web.mapping.axes[i].max, pad.mapping.axes[i].max);
  }
}
