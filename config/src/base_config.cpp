#include "craneassist/config/base_config.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <numbers>

#include "craneassist/config/quantity.hpp"
#include "craneassist/config/yaml_reader.hpp"
#include "embedded_configs.hpp"

namespace craneassist::config {
namespace {

constexpr const char* kFormat = "craneassist-base/1";

class Reader : public YamlReader {
 public:
  using YamlReader::YamlReader;

  // A required "VALUE UNIT, SOURCE" (one value, a source stated) within [lo, hi].
  double value(const YAML::Node& map, const std::string& key, const std::string& path,
               Dimension dimension, double lo, double hi, const std::string& range_text) const {
    const YAML::Node node = child(map, key, path);
    return convert(node, join(path, key), dimension, 1, lo, hi, range_text)[0];
  }

  // An optional one: fallback when absent.
  double optional_value(const YAML::Node& map, const std::string& key, const std::string& path,
                        Dimension dimension, double lo, double hi, const std::string& range_text,
                        double fallback) const {
    const YAML::Node node = map[key];
    if (!node.IsDefined() || node.IsNull()) return fallback;
    return convert(node, join(path, key), dimension, 1, lo, hi, range_text)[0];
  }

  std::vector<double> values(const YAML::Node& map, const std::string& key, const std::string& path,
                             Dimension dimension, std::size_t count, double lo, double hi,
                             const std::string& range_text) const {
    return convert(child(map, key, path), join(path, key), dimension, count, lo, hi, range_text);
  }

 private:
  std::vector<double> convert(const YAML::Node& node, const std::string& field, Dimension dimension,
                              std::size_t count, double lo, double hi,
                              const std::string& range_text) const {
    if (!node.IsScalar()) fail(node, field, "expected \"VALUE UNIT, SOURCE\"");
    std::string error;
    const auto q = parse_quantity(node.Scalar(), dimension, error);
    if (!q) fail(node, field, error);
    if (q->source == Source::kUnstated) {
      fail(node, field, "missing source (\"VALUE UNIT, SOURCE\": paper, assumed, derived, ...)");
    }
    if (q->si_values.size() != count) {
      fail(node, field,
           "expected " + std::to_string(count) + " value(s), got " +
               std::to_string(q->si_values.size()));
    }
    for (const double v : q->si_values) {
      if (!(v >= lo && v <= hi)) fail(node, field, "must be " + range_text);
    }
    return q->si_values;
  }
};

BaseConfig read_config(const Reader& r, const YAML::Node& root, std::string_view source) {
  BaseConfig c;
  c.source_name = std::string(source);
  r.check_keys(root, "", {"format", "name", "chassis", "drive", "crane_mount", "path_following"});
  const YAML::Node format = r.child(root, "format", "");
  if (!format.IsScalar() || format.Scalar() != kFormat) {
    r.fail(format, "format", std::string("expected ") + kFormat);
  }
  auto& m = c.model;
  m.name = r.text(root, "name", "");

  const std::string ch = "chassis";
  const YAML::Node chassis = r.child(root, "chassis", "");
  r.check_keys(chassis, ch,
               {"half_length", "half_width", "wheel_offset", "wheel_radius", "steer_max"});
  m.half_length_m = r.value(chassis, "half_length", ch, Dimension::kLength, 0.05, 20.0,
                            "between 0.05 m and 20 m");
  m.half_width_m =
      r.value(chassis, "half_width", ch, Dimension::kLength, 0.05, 20.0, "between 0.05 m and 20 m");
  m.wheel_offset_m = r.value(chassis, "wheel_offset", ch, Dimension::kLength, 0.0, m.half_width_m,
                             "between 0 and half_width");
  m.wheel_radius_m =
      r.value(chassis, "wheel_radius", ch, Dimension::kLength, 0.05, 5.0, "between 0.05 m and 5 m");
  m.steer_max_rad =
      r.value(chassis, "steer_max", ch, Dimension::kAngle, 1.0 * std::numbers::pi / 180.0,
              80.0 * std::numbers::pi / 180.0, "between 1 deg and 80 deg");

  const std::string dr = "drive";
  const YAML::Node drive = r.child(root, "drive", "");
  r.check_keys(drive, dr,
               {"motor_displacement", "gear_ratio", "pump_max_flow", "motor_max_speed",
                "time_constant", "arm_shares_pump", "shared_with_crane"});
  m.motor_displacement_m3 = r.value(drive, "motor_displacement", dr, Dimension::kVolume, 1e-7, 1e-2,
                                    "between 0.1 cm^3 and 10 L");
  m.gear_ratio = r.value(drive, "gear_ratio", dr, Dimension::kDimensionless, 0.01, 1000.0,
                         "between 0.01 and 1000");
  m.pump_max_flow_m3_s = r.value(drive, "pump_max_flow", dr, Dimension::kFlow, 1e-7, 1.0,
                                 "positive and at most 60000 L/min (1 m^3/s)");
  m.motor_speed_max_rad_s =
      r.optional_value(drive, "motor_max_speed", dr, Dimension::kAngularVelocity, 1e-3, 1e4,
                       "positive and at most 10000 rad/s", 0.0);
  m.time_constant_s =
      r.value(drive, "time_constant", dr, Dimension::kTime, 0.0, 10.0, "between 0 s and 10 s");
  c.arm_shares_pump = r.flag(drive, "arm_shares_pump", dr, false);
  c.shared_with_crane = r.flag(drive, "shared_with_crane", dr, false);

  const std::string mo = "crane_mount";
  const YAML::Node mount = r.child(root, "crane_mount", "");
  r.check_keys(mount, mo, {"position", "yaw"});
  const auto p = r.values(mount, "position", mo, Dimension::kLength, 3, -20.0, 20.0,
                          "within +-20 m of the chassis centre");
  m.crane_mount_m = Eigen::Vector3d(p[0], p[1], p[2]);
  m.crane_mount_yaw_rad = r.value(mount, "yaw", mo, Dimension::kAngle, -std::numbers::pi,
                                  std::numbers::pi, "within +-180 deg");

  const std::string pf = "path_following";
  const YAML::Node follow = r.child(root, "path_following", "");
  r.check_keys(follow, pf,
               {"k1", "k2", "k3", "epsilon", "tool_offset", "tool_height", "tool_error_ok",
                "tool_error_filter", "arm_position_gain"});
  auto& f = c.following;
  f.k1_1_m =
      r.value(follow, "k1", pf, Dimension::kInverseLength, 0.0, 100.0, "between 0 and 100 1/m");
  f.k2 = r.value(follow, "k2", pf, Dimension::kDimensionless, 1e-3, 1.0,
                 "in (0, 1] (the approach angle's sine)");
  f.k3_1_m = r.value(follow, "k3", pf, Dimension::kInverseLength, 1e-3, 100.0,
                     "between 0.001 and 100 1/m");
  f.epsilon_m =
      r.value(follow, "epsilon", pf, Dimension::kLength, 1e-3, 100.0, "between 1 mm and 100 m");
  f.tool_offset_m =
      r.value(follow, "tool_offset", pf, Dimension::kLength, -100.0, 100.0, "within +-100 m");
  f.tool_height_m =
      r.value(follow, "tool_height", pf, Dimension::kLength, -100.0, 100.0, "within +-100 m");
  f.tool_error_ok_m = r.value(follow, "tool_error_ok", pf, Dimension::kLength, 1e-4, 10.0,
                              "between 0.1 mm and 10 m");
  f.tool_error_filter_s =
      r.value(follow, "tool_error_filter", pf, Dimension::kTime, 0.0, 10.0, "between 0 s and 10 s");
  f.arm_position_gain_1_s = r.value(follow, "arm_position_gain", pf, Dimension::kInverseTime, 0.0,
                                    100.0, "between 0 and 100 1/s");
  return c;
}

}  // namespace

BaseConfig parse_base_config(std::string_view yaml_text, std::string_view source_name) {
  const Reader reader{std::string(source_name)};
  return read_yaml(yaml_text, source_name,
                   [&](const YAML::Node& root) { return read_config(reader, root, source_name); });
}

BaseConfig load_base_config(const std::filesystem::path& path) {
  return parse_base_config(read_yaml_file(path, "base config"), path.string());
}

BaseConfig default_base_config() {
  return parse_base_config(embedded::kMobileBaseYaml,
                           "<embedded config/machines/mobile_base.yaml>");
}

BaseConfig load_base_or_default(const std::string& path) {
  return path.empty() ? default_base_config() : load_base_config(path);
}

}  // namespace craneassist::config
