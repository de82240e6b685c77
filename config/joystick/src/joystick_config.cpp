#include "craneassist/config/joystick_config.hpp"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <sstream>

#include "craneassist/config/quantity.hpp"
#include "craneassist/config/yaml_reader.hpp"
#include "embedded_configs.hpp"

namespace craneassist::config {
namespace {

constexpr const char* kFormat = "craneassist-joystick/1";

class Reader : public YamlReader {
 public:
  using YamlReader::YamlReader;

  // A required value in [lo, hi].
  double value(const YAML::Node& map, const std::string& key, const std::string& path,
               Dimension dimension, double lo, double hi, const std::string& range_text) const {
    const YAML::Node node = child(map, key, path);
    const std::string field = join(path, key);
    if (!node.IsScalar()) fail(node, field, "expected a value");
    std::string error;
    const auto q = parse_quantity(node.Scalar(), dimension, error);
    if (!q) fail(node, field, error);
    if (q->si_values.size() != 1) fail(node, field, "expected one value");
    const double v = q->si_values[0];
    if (!(v >= lo && v <= hi)) fail(node, field, "must be " + range_text);
    return v;
  }
};

// The fields every stick axis has: its axis, deadband, expo and invert; max left to the caller.
input::AxisShape read_axis_common(const Reader& r, const YAML::Node& node, const std::string& path,
                                  std::initializer_list<const char*> keys) {
  r.check_keys(node, path, keys);
  input::AxisShape s;
  s.enabled = true;
  const std::string axis = r.text(node, "axis", path);
  if (!input::parse_gamepad_axis(axis, s.axis)) {
    r.fail(node["axis"], path + ".axis",
           "unknown axis '" + axis +
               "' (expected left_x, left_y, right_x, right_y, left_trigger or right_trigger)");
  }
  s.deadband = r.value(node, "deadband", path, Dimension::kDimensionless, 0.0, 0.9, "0 to 0.9");
  s.expo = r.value(node, "expo", path, Dimension::kDimensionless, 0.0, 1.0, "0 to 1");
  s.invert = r.flag(node, "invert", path, false);
  return s;
}

input::AxisShape read_axis(const Reader& r, const YAML::Node& node, const std::string& path,
                           input::SlewMode slew, bool lateral) {
  input::AxisShape s =
      read_axis_common(r, node, path, {"axis", "deadband", "expo", "max", "invert"});
  if (lateral && slew == input::SlewMode::kAngular) {
    s.max = r.value(node, "max", path, Dimension::kAngularVelocity, 0.0, 3.0,
                    "0 to 3 rad/s (slew: angular takes an angular velocity, e.g. 20 deg/s)");
  } else {
    s.max = r.value(node, "max", path, Dimension::kVelocity, 0.0, 5.0, "0 to 5 m/s");
  }
  return s;
}

// A drive-stick axis (sim --base): as a tip axis without max (a fraction of the drive's limit).
input::AxisShape read_drive_axis(const Reader& r, const YAML::Node& node, const std::string& path) {
  input::AxisShape s = read_axis_common(r, node, path, {"axis", "deadband", "expo", "invert"});
  s.max = 1.0;
  return s;
}

JoystickConfig read_config(const Reader& r, const YAML::Node& root, std::string_view source) {
  r.check_keys(root, "", {"format", "name", "input", "joystick", "keyboard"});
  const std::string format = r.text(root, "format", "");
  if (format != kFormat) r.fail(root["format"], "format", "expected " + std::string(kFormat));
  JoystickConfig c;
  c.source_name = std::string(source);
  c.name = r.text(root, "name", "");

  const YAML::Node in = r.child(root, "input", "");
  r.check_keys(in, "input", {"stale_timeout", "max_speed", "deadman_hold", "stop_latch"});
  c.monitor.stale_timeout_s =
      r.value(in, "stale_timeout", "input", Dimension::kTime, 0.005, 2.0, "5 ms to 2 s");
  c.monitor.max_speed_m_s =
      r.value(in, "max_speed", "input", Dimension::kVelocity, 0.01, 5.0, "0.01 to 5 m/s");
  // Optional (files written before these rules get the defaults).
  if (in["deadman_hold"].IsDefined()) {
    c.monitor.deadman_hold_s =
        r.value(in, "deadman_hold", "input", Dimension::kTime, 0.0, 2.0, "0 to 2 s");
  }
  if (in["stop_latch"].IsDefined()) {
    c.monitor.stop_latch_s =
        r.value(in, "stop_latch", "input", Dimension::kTime, 0.0, 10.0, "0 to 10 s");
  }

  const YAML::Node js = r.child(root, "joystick", "");
  r.check_keys(js, "joystick",
               {"frame", "slew", "deadman", "min_radius", "device", "axes", "drive"});
  auto& m = c.mapping;
  const std::string frame = r.text(js, "frame", "joystick");
  if (frame == "cylindrical") {
    m.frame = input::MappingFrame::kCylindrical;
  } else if (frame == "cartesian") {
    m.frame = input::MappingFrame::kCartesian;
  } else {
    r.fail(js["frame"], "joystick.frame",
           "unknown frame '" + frame + "' (expected cylindrical or cartesian)");
  }
  const std::string slew = r.optional_text(js, "slew", "joystick");
  if (slew.empty() || slew == "tangential") {
    m.slew = input::SlewMode::kTangential;
  } else if (slew == "angular") {
    m.slew = input::SlewMode::kAngular;
  } else {
    r.fail(js["slew"], "joystick.slew",
           "unknown slew mode '" + slew + "' (expected tangential or angular)");
  }
  const std::string deadman = r.text(js, "deadman", "joystick");
  if (!input::parse_gamepad_button(deadman, m.deadman)) {
    r.fail(js["deadman"], "joystick.deadman", "unknown button '" + deadman + "'");
  }
  m.min_radius_m =
      js["min_radius"].IsDefined()
          ? r.value(js, "min_radius", "joystick", Dimension::kLength, 0.01, 5.0, "0.01 to 5 m")
          : 0.3;
  if (js["device"].IsDefined()) {
    const YAML::Node dev = js["device"];
    r.check_keys(dev, "joystick.device", {"path", "name"});
    m.device_path = r.optional_text(dev, "path", "joystick.device");
    m.device_name = r.optional_text(dev, "name", "joystick.device");
  }
  const YAML::Node axes = r.child(js, "axes", "joystick");
  r.check_keys(axes, "joystick.axes", {"lateral", "radial", "vertical"});
  int mapped = 0;
  for (std::size_t i = 0; i < input::kOperatorAxisCount; ++i) {
    const char* key = input::to_string(static_cast<input::OperatorAxis>(i));
    if (!axes[key].IsDefined()) continue;
    m.axes[i] = read_axis(r, axes[key], std::string("joystick.axes.") + key, m.slew, i == 0);
    ++mapped;
  }
  if (mapped == 0) r.fail(axes, "joystick.axes", "map at least one of lateral, radial, vertical");
  if (js["drive"].IsDefined()) {
    const YAML::Node drive = js["drive"];
    r.check_keys(drive, "joystick.drive", {"speed", "curvature"});
    constexpr const char* kDriveKeys[input::kDriveAxisCount] = {"speed", "curvature"};
    for (std::size_t i = 0; i < input::kDriveAxisCount; ++i) {
      const std::string path = std::string("joystick.drive.") + kDriveKeys[i];
      const YAML::Node node = r.child(drive, kDriveKeys[i], "joystick.drive");
      m.drive[i] = read_drive_axis(r, node, path);
      // One gamepad axis moves one thing: the drive stick is not a tip axis.
      for (std::size_t j = 0; j < input::kOperatorAxisCount; ++j) {
        if (m.axes[j].enabled && m.axes[j].axis == m.drive[i].axis) {
          r.fail(node["axis"], path + ".axis",
                 std::string("this gamepad axis is already joystick.axes.") +
                     input::to_string(static_cast<input::OperatorAxis>(j)));
        }
      }
    }
    if (m.drive[0].axis == m.drive[1].axis) {
      r.fail(drive["curvature"]["axis"], "joystick.drive.curvature.axis",
             "the same gamepad axis as joystick.drive.speed");
    }
  }

  if (root["keyboard"].IsDefined()) {
    const YAML::Node kb = root["keyboard"];
    r.check_keys(kb, "keyboard", {"first_hold", "repeat_hold"});
    c.keyboard.first_hold_s =
        r.value(kb, "first_hold", "keyboard", Dimension::kTime, 0.05, 2.0, "50 ms to 2 s");
    c.keyboard.repeat_hold_s =
        r.value(kb, "repeat_hold", "keyboard", Dimension::kTime, 0.02, 1.0, "20 ms to 1 s");
  }
  return c;
}

}  // namespace

JoystickConfig parse_joystick_config(std::string_view yaml_text, std::string_view source_name) {
  const Reader reader{std::string(source_name)};
  return read_yaml(yaml_text, source_name,
                   [&](const YAML::Node& root) { return read_config(reader, root, source_name); });
}

JoystickConfig load_joystick_config(const std::filesystem::path& path) {
  return parse_joystick_config(read_yaml_file(path, "joystick mapping"), path.string());
}

JoystickConfig default_joystick_config() {
  return parse_joystick_config(embedded::kGamepadYaml, "<embedded config/joysticks/gamepad.yaml>");
}

JoystickConfig web_joystick_config() {
  return parse_joystick_config(embedded::kWebJoystickYaml, "<embedded config/joysticks/web.yaml>");
}

JoystickConfig drive_joystick_config() {
  return parse_joystick_config(embedded::kGamepadDriveYaml,
                               "<embedded config/joysticks/gamepad_drive.yaml>");
}

JoystickConfig web_drive_joystick_config() {
  return parse_joystick_config(embedded::kWebDriveJoystickYaml,
                               "<embedded config/joysticks/web_drive.yaml>");
}

}  // namespace craneassist::config
