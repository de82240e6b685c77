#include "craneassist/config/crane_config.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <numbers>
#include <span>
#include <sstream>
#include <stdexcept>

#include "craneassist/config/quantity.hpp"
#include "craneassist/config/yaml_reader.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/inverse_kinematics.hpp"
#include "craneassist/dynamics/valve_table.hpp"
#include "embedded_configs.hpp"

namespace craneassist::config {
namespace {

constexpr const char* kFormat = "craneassist-crane/1";

// A field's accepted values, [lo, hi], and how the message says so ("must be " + text). One
// definition per field: the reader checks the file's value with it, and the setters below the
// command line's overrides (docs/config.md#ranges).
struct FieldRange {
  double lo;
  double hi;
  const char* text;

  bool contains(double v) const { return v >= lo && v <= hi; }  // false for NaN
};

// The machine's geometry and masses, within what the simulator and the dynamics model run
// (docs/config.md#ranges; tests/config/test_config.cpp runs a model at these edges).
constexpr double kMaxLengthM = 100.0;  // every length, offset and centre of mass
constexpr FieldRange kLength{-kMaxLengthM, kMaxLengthM, "within +-100 m"};
constexpr FieldRange kPositiveLength{1e-6, kMaxLengthM, "positive and at most 100 m"};
constexpr FieldRange kAngleOffset{-2.0 * std::numbers::pi, 2.0 * std::numbers::pi,
                                  "within +-360 deg"};
constexpr FieldRange kBodyMass{1.0, 1e5, "between 1 kg and 100000 kg"};
// Each principal moment of inertia I = m r^2 with the radius of gyration r between these: a rod
// of 1.4 cm radius about its axis, a 100 m rod about its middle.
constexpr double kMinGyrationM = 0.01;
constexpr double kMaxGyrationM = 30.0;
// The fields the command line overrides too (the setters at the end of this file).
constexpr FieldRange kPayloadMass{0.0, 1e5, "between 0 and 100000 kg"};
constexpr FieldRange kPumpMaxFlow{1e-7, 1.0, "positive and at most 60000 L/min (1 m^3/s)"};
constexpr FieldRange kPrimeMoverPower{1.0, 1e7, "between 1 W and 10000 kW"};
constexpr FieldRange kFeedbackTimeout{1e-3, 1.0, "between 1 ms and 1 s"};

// The constant-pressure setpoint: positive and at most the relief setting; "" when it is.
std::string supply_pressure_problem(const dynamics::Pump& pump, double pa) {
  if (pa > 0.0 && pa <= pump.max_pressure_pa) return "";
  std::ostringstream why;
  why << "must be positive and at most max_pressure (the relief setting, "
      << pump.max_pressure_pa * 1e-6 << " MPa)";
  return why.str();
}

constexpr double kMaxGravityM_S2 = 20.0;
constexpr double kMaxGravityTiltDeg = 45.0;  // from the crane frame's down, -y

// Walks the YAML tree, converting and checking values; every failure names file, line, field.
class Reader : public YamlReader {
 public:
  using YamlReader::YamlReader;

  std::vector<double> values(const YAML::Node& map, const std::string& key, const std::string& path,
                             Dimension dimension, std::size_t count) {
    const YAML::Node node = child(map, key, path);
    const std::string field = join(path, key);
    if (!node.IsScalar()) fail(node, field, "expected \"VALUE UNIT, SOURCE\"");
    std::string error;
    const auto q = parse_quantity(node.Scalar(), dimension, error);
    if (!q) fail(node, field, error);
    if (count != 0 && q->si_values.size() != count) {
      fail(node, field,
           "expected " + std::to_string(count) + " value(s), got " +
               std::to_string(q->si_values.size()));
    }
    if (q->source == Source::kUnstated) ++unsourced_;
    return q->si_values;
  }

  double value(const YAML::Node& map, const std::string& key, const std::string& path,
               Dimension dimension) {
    return values(map, key, path, dimension, 1)[0];
  }

  // A value that must lie in [lo, hi].
  double value_in(const YAML::Node& map, const std::string& key, const std::string& path,
                  Dimension dimension, double lo, double hi, const std::string& range_text) {
    const double v = value(map, key, path, dimension);
    if (v < lo || v > hi) fail(map[key], join(path, key), "must be " + range_text);
    return v;
  }
  double value_in(const YAML::Node& map, const std::string& key, const std::string& path,
                  Dimension dimension, const FieldRange& range) {
    return value_in(map, key, path, dimension, range.lo, range.hi, range.text);
  }

  // An optional value in [lo, hi]: out keeps its value when the key is absent.
  void optional_value_in(const YAML::Node& map, const std::string& key, const std::string& path,
                         Dimension dimension, double lo, double hi, const std::string& range_text,
                         double& out) {
    if (map[key].IsDefined()) out = value_in(map, key, path, dimension, lo, hi, range_text);
  }

  // `count` values, each in the range.
  std::vector<double> values_in(const YAML::Node& map, const std::string& key,
                                const std::string& path, Dimension dimension, std::size_t count,
                                const FieldRange& range) {
    auto v = values(map, key, path, dimension, count);
    for (const double x : v) {
      if (!range.contains(x))
        fail(map[key], join(path, key), std::string("each must be ") + range.text);
    }
    return v;
  }

  int unsourced() const { return unsourced_; }

 private:
  int unsourced_ = 0;
};

Eigen::Matrix3d read_matrix3(Reader& r, const YAML::Node& map, const std::string& key,
                             const std::string& path) {
  const YAML::Node node = r.child(map, key, path);
  const std::string field = Reader::join(path, key);
  Eigen::Matrix3d m;
  if (!node.IsSequence() || node.size() != 3) r.fail(node, field, "expected 3 rows of 3 numbers");
  for (std::size_t i = 0; i < 3; ++i) {
    const YAML::Node row = node[i];
    if (!row.IsSequence() || row.size() != 3) r.fail(row, field, "expected 3 rows of 3 numbers");
    for (std::size_t j = 0; j < 3; ++j) {
      std::string error;
      const auto q = parse_quantity(row[j].Scalar(), Dimension::kDimensionless, error);
      if (!q || q->si_values.size() != 1) r.fail(row[j], field, "not a number");
      m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = q->si_values[0];
    }
  }
  if (!(m.transpose() * m).isApprox(Eigen::Matrix3d::Identity(), 1e-9)) {
    r.fail(node, field, "must be orthonormal (a rotation or an axis permutation)");
  }
  return m;
}

dynamics::Cylinder read_cylinder(Reader& r, const YAML::Node& node, const std::string& path,
                                 const dynamics::DhJoint& joint) {
  using dynamics::LinkageType;
  r.check_keys(node, path,
               {"name", "linkage", "arm", "length_at_zero", "l1", "l2", "angle_offset",
                "coefficients", "bore", "rod", "area_a", "area_b", "differential_spool", "stroke",
                "max_speed", "max_acceleration", "friction"});
  dynamics::Cylinder c;
  c.name = node["name"].IsDefined() ? node["name"].Scalar() : joint.name;
  const std::string linkage = r.text(node, "linkage", path);
  if (linkage == "constant_arm") {
    c.linkage = LinkageType::kConstantArm;
    c.arm_m = r.value_in(node, "arm", path, Dimension::kLength, kLength);
    c.c0_m = r.value_in(node, "length_at_zero", path, Dimension::kLength, kLength);
    if (c.arm_m == 0.0) r.fail(node["arm"], path + ".arm", "must not be zero");
  } else if (linkage == "triangle") {
    c.linkage = LinkageType::kTriangle;
    c.l1_m = r.value_in(node, "l1", path, Dimension::kLength, kPositiveLength);
    c.l2_m = r.value_in(node, "l2", path, Dimension::kLength, kPositiveLength);
    c.angle_offset_rad = r.value_in(node, "angle_offset", path, Dimension::kAngle, kAngleOffset);
  } else if (linkage == "polynomial") {
    c.linkage = LinkageType::kPolynomial;
    c.poly_coeffs = r.values(node, "coefficients", path, Dimension::kLength, 0);
    if (c.poly_coeffs.size() < 2) {
      r.fail(node["coefficients"], path + ".coefficients", "needs at least 2 coefficients");
    }
  } else {
    r.fail(node["linkage"], path + ".linkage",
           "unknown linkage '" + linkage + "' (expected constant_arm, triangle or polynomial)");
  }

  const bool by_bore = node["bore"].IsDefined() || node["rod"].IsDefined();
  const bool by_area = node["area_a"].IsDefined() || node["area_b"].IsDefined();
  if (by_bore == by_area) {
    r.fail(node, path, "give either bore and rod, or area_a and area_b (not both)");
  }
  if (by_bore) {
    const double bore = r.value_in(node, "bore", path, Dimension::kLength, 1e-4, 2.0, "positive");
    const double rod =
        r.value_in(node, "rod", path, Dimension::kLength, 0.0, bore, "between 0 and the bore");
    c.area_a_m2 = 0.25 * M_PI * bore * bore;
    c.area_b_m2 = 0.25 * M_PI * (bore * bore - rod * rod);
  } else {
    c.area_a_m2 = r.value_in(node, "area_a", path, Dimension::kArea, 1e-8, 10.0, "positive");
    c.area_b_m2 = r.value_in(node, "area_b", path, Dimension::kArea, 1e-8, 10.0, "positive");
  }
  c.differential_spool = r.flag(node, "differential_spool", path, false);
  if (c.differential_spool && c.area_b_m2 >= c.area_a_m2) {
    r.fail(node["differential_spool"], path + ".differential_spool",
           "needs a rod-side area smaller than the piston area");
  }
  c.stroke_m = r.value_in(node, "stroke", path, Dimension::kLength, 1e-4, 50.0, "positive");
  c.v_max_m_s = r.value_in(node, "max_speed", path, Dimension::kVelocity, 1e-6, 10.0,
                           "positive and at most 10 m/s");
  c.a_max_m_s2 = r.value_in(node, "max_acceleration", path, Dimension::kAcceleration, 1e-6, 100.0,
                            "positive and at most 100 m/s^2");
  // Optional seal and guide friction (docs/loads.md).
  if (const auto friction = r.optional_section(node, "friction", path,
                                               {"coulomb_extend", "coulomb_retract", "viscous"})) {
    const YAML::Node& f = *friction;
    const std::string fp = path + ".friction";
    c.friction.coulomb_extend_n =
        r.value_in(f, "coulomb_extend", fp, Dimension::kForce, 0.0, 1e7, "between 0 and 10000 kN");
    c.friction.coulomb_retract_n =
        r.value_in(f, "coulomb_retract", fp, Dimension::kForce, 0.0, 1e7, "between 0 and 10000 kN");
    c.friction.viscous_n_s_m =
        r.value_in(f, "viscous", fp, Dimension::kDamping, 0.0, 1e8, "between 0 and 100000 kN*s/m");
  }

  // The joint range must fit the stroke, and the torque arm must keep its sign over it.
  constexpr int kSamples = 64;
  double c_min = 1e300, c_max = -1e300;
  double arm_sign = 0.0;
  for (int k = 0; k <= kSamples; ++k) {
    const double q = joint.q_min + (joint.q_max - joint.q_min) * k / kSamples;
    const double len = dynamics::cylinder_length(c, q);
    const double arm = dynamics::cylinder_arm(c, q);
    if (!(std::abs(len) <= kMaxLengthM)) {
      const bool poly = c.linkage == LinkageType::kPolynomial;
      r.fail(node[poly ? "coefficients" : "linkage"], path + (poly ? ".coefficients" : ".linkage"),
             "the cylinder length leaves +-100 m inside the joint range");
    }
    if (!std::isfinite(arm) || std::abs(arm) < 1e-6 || (arm_sign != 0.0 && arm * arm_sign < 0.0)) {
      r.fail(node["linkage"], path + ".linkage",
             "the torque arm dc/dq vanishes or changes sign inside the joint range");
    }
    arm_sign = arm;
    c_min = std::min(c_min, len);
    c_max = std::max(c_max, len);
  }
  if (c_max - c_min > c.stroke_m * 1.02 + 1e-3) {
    std::ostringstream why;
    why << "the joint range needs " << (c_max - c_min) * 1e3 << " mm of stroke, the cylinder has "
        << c.stroke_m * 1e3 << " mm";
    r.fail(node["stroke"], path + ".stroke", why.str());
  }
  return c;
}

void read_joints(Reader& r, const YAML::Node& root, dynamics::CraneModel& model) {
  const YAML::Node joints = r.child(root, "joints", "");
  if (!joints.IsSequence() || joints.size() == 0 ||
      joints.size() > static_cast<std::size_t>(dynamics::kMaxJoints)) {
    r.fail(joints, "joints",
           "expected a list of 1 to " + std::to_string(dynamics::kMaxJoints) + " joints");
  }
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const YAML::Node j = joints[i];
    const std::string path = "joints[" + std::to_string(i) + "]";
    r.check_keys(j, path,
                 {"name", "type", "a", "alpha", "d", "theta_offset", "min", "max", "cylinder"});
    dynamics::DhJoint joint;
    joint.name = r.text(j, "name", path);
    for (const auto& other : model.joints) {
      if (other.name == joint.name) r.fail(j["name"], path + ".name", "duplicate joint name");
    }
    const std::string type = r.text(j, "type", path);
    if (type == "revolute") {
      joint.type = dynamics::JointType::kRevolute;
    } else if (type == "prismatic") {
      joint.type = dynamics::JointType::kPrismatic;
    } else {
      r.fail(j["type"], path + ".type", "expected revolute or prismatic, got '" + type + "'");
    }
    const Dimension qdim =
        joint.type == dynamics::JointType::kRevolute ? Dimension::kAngle : Dimension::kLength;
    joint.a_m = r.value_in(j, "a", path, Dimension::kLength, kLength);
    joint.alpha_rad = r.value_in(j, "alpha", path, Dimension::kAngle, kAngleOffset);
    joint.d_m = r.value_in(j, "d", path, Dimension::kLength, kLength);
    joint.theta_rad = r.value_in(j, "theta_offset", path, Dimension::kAngle, kAngleOffset);
    joint.q_min = r.value(j, "min", path, qdim);
    joint.q_max = r.value(j, "max", path, qdim);
    if (!(joint.q_min < joint.q_max)) r.fail(j["max"], path + ".max", "must be greater than min");
    if (joint.type == dynamics::JointType::kRevolute &&
        (joint.q_min < -M_PI - 1e-9 || joint.q_max > M_PI + 1e-9)) {
      r.fail(j["min"], path + ".min", "a revolute range must lie within [-180, 180] deg");
    }
    if (joint.type == dynamics::JointType::kPrismatic) {
      for (const char* end : {"min", "max"}) {
        if (!kLength.contains(end[1] == 'i' ? joint.q_min : joint.q_max)) {
          r.fail(j[end], path + "." + end, "a prismatic range must lie within +-100 m");
        }
      }
    }
    model.cylinders.push_back(
        read_cylinder(r, r.child(j, "cylinder", path), path + ".cylinder", joint));
    model.joints.push_back(joint);
  }
}

// The principal moments of a rigid body: each m r^2 with the radius of gyration r in
// [kMinGyrationM, kMaxGyrationM] (so the tensor is positive definite), and none larger than the
// sum of the other two (the triangle inequality every mass distribution meets).
void check_inertia(Reader& r, const YAML::Node& node, const std::string& field, double mass_kg,
                   const Eigen::Vector3d& moments) {
  const double lo = mass_kg * kMinGyrationM * kMinGyrationM;
  const double hi = mass_kg * kMaxGyrationM * kMaxGyrationM;
  for (int i = 0; i < 3; ++i) {
    if (!(moments[i] >= lo && moments[i] <= hi)) {
      std::ostringstream why;
      why << "each principal moment must be between m (1 cm)^2 and m (30 m)^2, " << lo << " to "
          << hi << " kg*m^2 for the mass of " << mass_kg << " kg (radius of gyration 1 cm to 30 m)";
      r.fail(node, field, why.str());
    }
  }
  for (int i = 0; i < 3; ++i) {
    const double others = moments[(i + 1) % 3] + moments[(i + 2) % 3];
    if (moments[i] > others * (1.0 + 1e-9)) {
      std::ostringstream why;
      why << "not a rigid body's: principal moment " << i + 1 << " (" << moments[i]
          << " kg*m^2) exceeds the sum of the other two (" << others << " kg*m^2)";
      r.fail(node, field, why.str());
    }
  }
}

// Gravity in the base frame: at most kMaxGravityM_S2, and (unless zero) pointing within
// kMaxGravityTiltDeg of the crane frame's down (-y, as tip commands are given).
void check_gravity(Reader& r, const YAML::Node& node, const std::string& field,
                   const Eigen::Vector3d& g, const Eigen::Matrix3d& crane_from_base) {
  const double magnitude = g.norm();
  if (!(magnitude <= kMaxGravityM_S2)) {
    std::ostringstream why;
    why << "magnitude " << magnitude << " m/s^2 must be at most 20 m/s^2 (9.81 on earth)";
    r.fail(node, field, why.str());
  }
  if (magnitude == 0.0) return;
  const double down = -(crane_from_base * g).y() / magnitude;  // cos of the angle from down
  if (!(down >= std::cos(kMaxGravityTiltDeg * std::numbers::pi / 180.0) - 1e-12)) {
    std::ostringstream why;
    why << "must point down, within 45 deg of the crane frame's -y (frames.crane_from_base maps "
           "it): it is "
        << std::acos(std::clamp(down, -1.0, 1.0)) * 180.0 / std::numbers::pi << " deg from it";
    r.fail(node, field, why.str());
  }
}

void read_bodies(Reader& r, const YAML::Node& root, dynamics::CraneModel& model) {
  const YAML::Node bodies = r.child(root, "bodies", "");
  if (!bodies.IsSequence() || bodies.size() == 0) r.fail(bodies, "bodies", "expected a list");
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const YAML::Node b = bodies[i];
    const std::string path = "bodies[" + std::to_string(i) + "]";
    r.check_keys(b, path, {"name", "frame", "mass", "com", "inertia"});
    dynamics::Body body;
    body.name = r.text(b, "name", path);
    const YAML::Node frame = r.child(b, "frame", path);
    try {
      body.frame = frame.as<int>();
    } catch (const YAML::Exception&) {
      r.fail(frame, path + ".frame", "expected a whole number");
    }
    if (body.frame < 1 || body.frame > model.dof()) {
      r.fail(frame, path + ".frame", "must name a joint frame 1.." + std::to_string(model.dof()));
    }
    body.mass_kg = r.value_in(b, "mass", path, Dimension::kMass, kBodyMass);
    const auto com = r.values_in(b, "com", path, Dimension::kLength, 3, kLength);
    body.com_m = Eigen::Vector3d(com[0], com[1], com[2]);
    const auto inertia = r.values(b, "inertia", path, Dimension::kInertia, 3);
    body.inertia_diag_kgm2 = Eigen::Vector3d(inertia[0], inertia[1], inertia[2]);
    check_inertia(r, b["inertia"], path + ".inertia", body.mass_kg, body.inertia_diag_kgm2);
    model.bodies.push_back(body);
  }
  const YAML::Node payload = r.child(root, "payload", "");
  r.check_keys(payload, "payload", {"mass"});
  dynamics::Body p;
  p.name = dynamics::kPayloadBody;
  p.frame = model.dof();
  p.mass_kg = r.value_in(payload, "mass", "payload", Dimension::kMass, kPayloadMass);
  model.bodies.push_back(p);
}

// The index of the joint of that name, or model.joints.size() when there is none.
std::size_t joint_index(const dynamics::CraneModel& model, const std::string& name) {
  for (std::size_t i = 0; i < model.joints.size(); ++i) {
    if (model.joints[i].name == name) return i;
  }
  return model.joints.size();
}

// hydraulics.valves.tables: the measured characteristic of some sections, by joint name
// (craneassist calibrate writes this block); the others keep the straight line.
void read_valve_tables(Reader& r, const YAML::Node& tables, const std::string& path,
                       dynamics::CraneModel& model) {
  if (!tables.IsMap()) r.fail(tables, path, "expected joint: {command, velocity} entries");
  model.valves.tables.assign(model.cylinders.size(), dynamics::ValveTable{});
  for (const auto& kv : tables) {
    const std::string name = kv.first.Scalar();
    const std::string tp = path + "." + name;
    const std::size_t index = joint_index(model, name);
    if (index == model.joints.size()) r.fail(kv.first, tp, "no joint of that name");
    const YAML::Node entry = kv.second;
    r.check_keys(entry, tp, {"command", "velocity", "time_constant", "delay"});
    dynamics::ValveTable table;
    table.command = r.values(entry, "command", tp, Dimension::kDimensionless, 0);
    table.velocity_m_s = r.values(entry, "velocity", tp, Dimension::kVelocity, 0);
    r.optional_value_in(entry, "time_constant", tp, Dimension::kTime, 0.0, 5.0, "between 0 and 5 s",
                        table.time_constant_s);
    r.optional_value_in(entry, "delay", tp, Dimension::kTime, 0.0, 1.0, "between 0 and 1 s",
                        table.delay_s);
    if (const std::string why = dynamics::check_valve_table(table); !why.empty()) {
      const bool about_command = why.rfind("command", 0) == 0;  // else about the velocities
      r.fail(entry[about_command ? "command" : "velocity"],
             tp + (about_command ? ".command" : ".velocity"), why);
    }
    model.valves.tables[index] = std::move(table);
  }
}

// hydraulics.mhsb (docs/mhsb.md): the boost modules and the servo-valves of an MHSB arm. The main
// pump must be a constant-pressure pump: its setpoint is the circuit's P0.
void read_mhsb(Reader& r, const YAML::Node& node, dynamics::CraneModel& model) {
  const std::string mp = "hydraulics.mhsb";
  r.check_keys(node, mp,
               {"modules", "servo_pump_max_flow", "max_boost", "servo_pump_efficiency",
                "tank_pressure", "velocity_limit", "servo_valve"});
  if (model.pump.mode != dynamics::PumpMode::kConstantPressure) {
    r.fail(node, mp,
           "an MHSB circuit needs a constant-pressure main pump (hydraulics.pump.mode: "
           "constant-pressure; its supply_pressure is P0)");
  }
  dynamics::Mhsb m;
  const double modules = r.value_in(node, "modules", mp, Dimension::kDimensionless, 0.0, 16.0,
                                    "a whole number from 0 to 16");
  if (modules != std::floor(modules)) {
    r.fail(node["modules"], mp + ".modules", "must be a whole number from 0 to 16");
  }
  m.modules = static_cast<int>(modules);
  m.servo_pump_max_flow_m3_s =
      r.value_in(node, "servo_pump_max_flow", mp, Dimension::kFlow, kPumpMaxFlow);
  m.max_boost_pa =
      r.value_in(node, "max_boost", mp, Dimension::kPressure, 1e4, 1e8, "between 0.1 and 1000 bar");
  m.servo_pump_efficiency = r.value_in(node, "servo_pump_efficiency", mp, Dimension::kDimensionless,
                                       0.05, 1.0, "between 0.05 and 1");
  m.tank_pressure_pa = r.value_in(node, "tank_pressure", mp, Dimension::kPressure, 0.0,
                                  0.5 * model.pump.supply_pressure_pa,
                                  "between 0 and half the main pump's supply pressure");
  m.velocity_limit_m_s = r.value_in(node, "velocity_limit", mp, Dimension::kVelocity, 1e-4, 10.0,
                                    "between 0.1 mm/s and 10 m/s");
  const YAML::Node sv = r.child(node, "servo_valve", mp);
  const std::string svp = mp + ".servo_valve";
  r.check_keys(sv, svp, {"rated_flow", "rated_pressure_drop", "leakage"});
  m.valve.rated_flow_m3_s = r.value_in(sv, "rated_flow", svp, Dimension::kFlow, kPumpMaxFlow);
  m.valve.rated_pressure_drop_pa = r.value_in(sv, "rated_pressure_drop", svp, Dimension::kPressure,
                                              1e4, 1e8, "between 0.1 and 1000 bar");
  m.valve.leakage_m3_s =
      r.value_in(sv, "leakage", svp, Dimension::kFlow, 0.0, 1.0, "between 0 and 60000 L/min");
  model.mhsb = m;
}

void read_hydraulics(Reader& r, const YAML::Node& root, dynamics::CraneModel& model) {
  const YAML::Node h = r.child(root, "hydraulics", "");
  r.check_keys(h, "hydraulics", {"pump", "valves", "mhsb", "load_holding"});
  const YAML::Node pump = r.child(h, "pump", "hydraulics");
  const std::string pp = "hydraulics.pump";
  r.check_keys(pump, pp,
               {"mode", "max_flow", "max_pressure", "ls_margin", "prime_mover_power",
                "standby_pressure", "supply_pressure"});
  auto& p = model.pump;
  p.max_flow_m3_s = r.value_in(pump, "max_flow", pp, Dimension::kFlow, kPumpMaxFlow);
  p.max_pressure_pa = r.value_in(pump, "max_pressure", pp, Dimension::kPressure, 1e5, 1e8,
                                 "between 1 and 1000 bar");
  p.ls_margin_pa = r.value_in(pump, "ls_margin", pp, Dimension::kPressure, 1e4, p.max_pressure_pa,
                              "positive and below max_pressure");
  p.prime_mover_power_w =
      r.value_in(pump, "prime_mover_power", pp, Dimension::kPower, kPrimeMoverPower);
  p.standby_pressure_pa = r.value_in(pump, "standby_pressure", pp, Dimension::kPressure, 0.0,
                                     p.max_pressure_pa, "between 0 and max_pressure");
  // Optional: the mode defaults to load sensing; the constant-pressure setpoint is needed in that
  // mode only, but may be given in either (--pump-mode cp then uses it).
  if (pump["mode"].IsDefined()) p.mode = r.one_of(pump, "mode", pp, dynamics::kPumpModes);
  if (pump["supply_pressure"].IsDefined()) {
    p.supply_pressure_pa = r.value(pump, "supply_pressure", pp, Dimension::kPressure);
    if (const std::string why = supply_pressure_problem(p, p.supply_pressure_pa); !why.empty()) {
      r.fail(pump["supply_pressure"], pp + ".supply_pressure", why);
    }
  } else if (p.mode == dynamics::PumpMode::kConstantPressure) {
    r.fail(pump, pp + ".supply_pressure",
           "missing (the constant-pressure mode needs its setpoint)");
  }

  const YAML::Node valves = r.child(h, "valves", "hydraulics");
  const std::string vp = "hydraulics.valves";
  r.check_keys(valves, vp, {"dead_zone", "time_constant", "delay", "stroke_time", "tables"});
  auto& v = model.valves;
  v.dead_zone = r.value_in(valves, "dead_zone", vp, Dimension::kDimensionless, 0.0, 0.95,
                           "between 0 and 0.95");
  v.time_constant_s =
      r.value_in(valves, "time_constant", vp, Dimension::kTime, 0.0, 5.0, "between 0 and 5 s");
  v.delay_s = r.value_in(valves, "delay", vp, Dimension::kTime, 0.0, 2.0, "between 0 and 2 s");
  if (valves["stroke_time"].IsDefined()) {
    v.stroke_time_s = r.value_in(valves, "stroke_time", vp, Dimension::kTime, 0.0, 5.0,
                                 "between 0 and 5 s (0: no slew-rate limit)");
  }
  if (valves["tables"].IsDefined()) read_valve_tables(r, valves["tables"], vp + ".tables", model);
  if (h["mhsb"].IsDefined() && !h["mhsb"].IsNull()) read_mhsb(r, h["mhsb"], model);
  // Optional load-holding valves (docs/loads.md); left out: loads are held up to the pump's
  // relief, and a load beyond it runs ahead of its section (no valve bounds it).
  if (const auto holding =
          r.optional_section(h, "load_holding", "hydraulics", {"relief", "relief_flow"})) {
    const YAML::Node& lh = *holding;
    const std::string lp = "hydraulics.load_holding";
    model.load_holding.relief_pa =
        r.value_in(lh, "relief", lp, Dimension::kPressure, p.max_pressure_pa, 1e8,
                   "at least the pump's max_pressure and at most 1000 bar");
    model.load_holding.relief_flow_m3_s =
        r.value_in(lh, "relief_flow", lp, Dimension::kFlow, 0.0, 1e-2, "between 0 and 600 L/min");
  }
}

// The hanging grapple's values in `node` (at `path`) into g: all of them (required), or those the
// node names (the others stay).
void read_grapple_values(Reader& r, const YAML::Node& node, const std::string& path, bool required,
                         dynamics::HangingGrapple& g) {
  const auto given = [&](const char* key) { return required || node[key].IsDefined(); };
  if (given("hanger_length")) {
    g.com_below_m = r.value_in(node, "hanger_length", path, Dimension::kLength, 0.05, 10.0,
                               "between 5 cm and 10 m");
  }
  if (given("load_below")) {
    g.load_below_m = r.value_in(node, "load_below", path, Dimension::kLength, 0.05, 10.0,
                                "between 5 cm and 10 m");
  }
  if (given("damping")) {
    g.damping_n_m_s_rad = r.value_in(node, "damping", path, Dimension::kRotaryDamping, 0.0, 1e6,
                                     "between 0 and 1000 kN*m*s/rad");
  }
}

// Optional hanging grapple (docs/sway.md): the bodies at the tip and the payload hang from it on a
// two-axis link in the simulator.
void read_grapple(Reader& r, const YAML::Node& root, dynamics::CraneModel& model) {
  const auto section =
      r.optional_section(root, "grapple", "", {"hanger_length", "load_below", "damping"});
  if (section) read_grapple_values(r, *section, "grapple", true, model.grapple);
}

// The simulated machine's swing sensor and grapple, where they differ from the default (an exact
// sensor) and the controller's model (docs/sway.md).
void read_simulated_grapple(Reader& r, const YAML::Node& sim, CraneConfig& cfg) {
  const std::string sp = "simulation.swing_sensor";
  if (sim["swing_sensor"].IsDefined() && sim["swing_sensor"].IsScalar()) {
    const std::string text = r.text(sim, "swing_sensor", "simulation");
    if (text != "none") {
      r.fail(sim["swing_sensor"], sp, "expected none or {noise, resolution}, got '" + text + "'");
    }
    cfg.simulation.swing_sensor = false;
  } else if (const auto sensor =
                 r.optional_section(sim, "swing_sensor", "simulation", {"noise", "resolution"})) {
    const YAML::Node& ss = *sensor;
    cfg.simulation.swing_noise_rad =
        r.value_in(ss, "noise", sp, Dimension::kAngle, 0.0, 0.1, "between 0 and 5.7 deg");
    cfg.simulation.swing_resolution_rad =
        r.value_in(ss, "resolution", sp, Dimension::kAngle, 0.0, 0.1, "between 0 and 5.7 deg");
  }
  const auto section =
      r.optional_section(sim, "grapple", "simulation", {"hanger_length", "load_below", "damping"});
  if (!section) return;
  if (!cfg.model.grapple.hangs()) {
    r.fail(*section, "simulation.grapple",
           "the crane has no hanging grapple (no grapple section) to differ from");
  }
  dynamics::HangingGrapple g = cfg.model.grapple;
  read_grapple_values(r, *section, "simulation.grapple", false, g);
  cfg.simulation.grapple = g;
}

// The valve deviation fields present in node (simulation.valves, or a joint's entry in it), each
// read once and given to every section in `sections`.
void read_valve_deviation(Reader& r, const YAML::Node& node, const std::string& path,
                          std::span<dynamics::ValveDeviation> sections) {
  using D = dynamics::ValveDeviation;
  auto field = [&](const char* key, Dimension dim, double lo, double hi, const char* range,
                   double D::*member) {
    if (!node[key].IsDefined()) return;
    const double v = r.value_in(node, key, path, dim, lo, hi, range);
    for (auto& section : sections) section.*member = v;
  };
  field("time_constant", Dimension::kTime, 0.0, 5.0, "between 0 and 5 s", &D::time_constant_s);
  field("delay", Dimension::kTime, 0.0, 1.0, "between 0 and 1 s", &D::delay_s);
  field("dead_zone", Dimension::kDimensionless, 0.0, 0.95, "between 0 and 0.95", &D::dead_zone);
  field("gain", Dimension::kDimensionless, 0.1, 10.0, "between 0.1 and 10", &D::gain);
  field("shape", Dimension::kDimensionless, 0.2, 5.0, "between 0.2 and 5", &D::shape);
  field("hysteresis", Dimension::kDimensionless, 0.0, 0.5, "between 0 and 0.5", &D::hysteresis);
}

// simulation.valves, simulation.joint_sensors, simulation.feedback: where the simulated machine
// differs from the controller's model (docs/valves.md#the-machine-it-meets).
void read_simulated_machine(Reader& r, const YAML::Node& sim, const std::string& prefix,
                            CraneConfig& cfg) {
  const auto& joints = cfg.model.joints;
  if (sim["spool_time_constant"].IsDefined()) {
    const double tau = r.value_in(sim, "spool_time_constant", prefix, Dimension::kTime, 0.0, 5.0,
                                  "between 0 and 5 s");
    for (auto& v : cfg.simulation.valves) v.time_constant_s = tau;
  }
  if (const YAML::Node valves = sim["valves"]; valves.IsDefined() && !valves.IsNull()) {
    const std::string vp = prefix + ".valves";
    if (!valves.IsMap()) r.fail(valves, vp, "expected a mapping of fields");
    static constexpr std::array kFields{"time_constant", "delay", "dead_zone",
                                        "gain",          "shape", "hysteresis"};
    // The fields for every section first, then each joint's own.
    read_valve_deviation(r, valves, vp, cfg.simulation.valves);
    for (const auto& kv : valves) {
      const std::string key = kv.first.Scalar();
      if (std::find(kFields.begin(), kFields.end(), key) != kFields.end()) continue;
      const std::size_t index = joint_index(cfg.model, key);
      if (index == joints.size()) {
        std::string list;
        for (const char* f : kFields) list += std::string(f) + ", ";
        for (const auto& j : joints) list += j.name + (&j == &joints.back() ? "" : ", ");
        r.fail(kv.first, vp + "." + key, "unknown field (expected one of: " + list + ")");
      }
      const std::string jp = vp + "." + key;
      r.check_keys(kv.second, jp,
                   {"time_constant", "delay", "dead_zone", "gain", "shape", "hysteresis"});
      read_valve_deviation(r, kv.second, jp, std::span(&cfg.simulation.valves[index], 1));
    }
  }
  auto& js = cfg.simulation.joints;
  if (const auto sensors = r.optional_section(
          sim, "joint_sensors", prefix,
          {"angle_noise", "angle_resolution", "length_noise", "length_resolution", "delay"})) {
    const YAML::Node& n = *sensors;
    const std::string p = prefix + ".joint_sensors";
    const std::string angle = "between 0 and 5.7 deg", length = "between 0 and 0.1 m";
    r.optional_value_in(n, "angle_noise", p, Dimension::kAngle, 0.0, 0.1, angle,
                        js.angle_noise_rad);
    r.optional_value_in(n, "angle_resolution", p, Dimension::kAngle, 0.0, 0.1, angle,
                        js.angle_resolution_rad);
    r.optional_value_in(n, "length_noise", p, Dimension::kLength, 0.0, 0.1, length,
                        js.length_noise_m);
    r.optional_value_in(n, "length_resolution", p, Dimension::kLength, 0.0, 0.1, length,
                        js.length_resolution_m);
    r.optional_value_in(n, "delay", p, Dimension::kTime, 0.0, 1.0, "between 0 and 1 s", js.delay_s);
  }
  if (const auto fb = r.optional_section(sim, "feedback", prefix, {"delay", "jitter"})) {
    const YAML::Node& n = *fb;
    const std::string p = prefix + ".feedback";
    r.optional_value_in(n, "delay", p, Dimension::kTime, 0.0, 1.0, "between 0 and 1 s",
                        js.feedback_delay_s);
    r.optional_value_in(n, "jitter", p, Dimension::kTime, 0.0, 1.0, "between 0 and 1 s",
                        js.feedback_jitter_s);
  }
}

// Optional rated load against reach (docs/loads.md).
void read_load_chart(Reader& r, const YAML::Node& root, LoadChart& chart) {
  const auto section = r.optional_section(root, "load_chart", "", {"reach", "rated_load"});
  if (!section) return;
  const YAML::Node& node = *section;
  chart.reach_m = r.values(node, "reach", "load_chart", Dimension::kLength, 0);
  chart.rated_kg = r.values(node, "rated_load", "load_chart", Dimension::kMass, 0);
  if (chart.reach_m.size() != chart.rated_kg.size()) {
    r.fail(node["rated_load"], "load_chart.rated_load",
           "needs one value per reach (" + std::to_string(chart.reach_m.size()) + "), got " +
               std::to_string(chart.rated_kg.size()));
  }
  for (std::size_t k = 0; k < chart.reach_m.size(); ++k) {
    if (!(chart.reach_m[k] > 0.0 && chart.reach_m[k] <= 100.0) ||
        (k > 0 && !(chart.reach_m[k] > chart.reach_m[k - 1]))) {
      r.fail(node["reach"], "load_chart.reach", "must be positive, increasing and at most 100 m");
    }
    if (!(chart.rated_kg[k] > 0.0 && chart.rated_kg[k] <= 1e5)) {
      r.fail(node["rated_load"], "load_chart.rated_load",
             "each must be positive and at most 100000 kg");
    }
  }
}

// `backend: sim | can` and the optional `can:` section; both may be left out (sim).
void read_backend(Reader& r, const YAML::Node& root, BackendSettings& backend) {
  const YAML::Node kind = root["backend"];
  if (kind.IsDefined() && !kind.IsNull()) {
    const std::string text = r.text(root, "backend", "");
    if (const auto parsed = parse_backend_kind(text)) {
      backend.kind = *parsed;
    } else {
      r.fail(kind, "backend",
             "unknown backend '" + text + "' (expected " + alternatives(kBackendKinds) + ")");
    }
  }
  const YAML::Node can = root["can"];
  if (!can.IsDefined() || can.IsNull()) return;
  r.check_keys(can, "can", {"interface", "mapping", "feedback_timeout"});
  if (can["interface"].IsDefined()) {
    backend.can.interface = r.text(can, "interface", "can");
    const auto& name = backend.can.interface;
    // Linux interface names: 1..15 characters, no '/', no whitespace.
    if (name.empty() || name.size() > 15 || name.find_first_of("/ \t") != std::string::npos) {
      r.fail(can["interface"], "can.interface", "not a network interface name (1-15 characters)");
    }
  }
  if (can["mapping"].IsDefined()) {
    std::filesystem::path mapping(r.text(can, "mapping", "can"));
    const std::filesystem::path source(r.file());
    if (mapping.is_relative() && source.has_parent_path() && r.file().front() != '<') {
      mapping = source.parent_path() / mapping;
    }
    backend.can.mapping = mapping.string();
  }
  if (can["feedback_timeout"].IsDefined()) {
    backend.can.feedback_timeout_s =
        r.value_in(can, "feedback_timeout", "can", Dimension::kTime, kFeedbackTimeout);
  }
}

CraneConfig read_config(Reader& r, const YAML::Node& root, std::string_view source_name) {
  CraneConfig cfg;
  cfg.source_name = std::string(source_name);
  if (!root.IsMap()) r.fail(root, "", "expected a mapping at the top level");
  r.check_keys(root, "",
               {"format", "name", "frames", "joints", "bodies", "payload", "hydraulics", "control",
                "scaling", "redundancy", "simulation", "backend", "can", "load_chart", "grapple"});
  const std::string format = r.text(root, "format", "");
  if (format != kFormat) {
    r.fail(root["format"], "format",
           "unsupported format '" + format + "' (expected " + kFormat + ")");
  }
  auto& model = cfg.model;
  model.name = r.text(root, "name", "");

  const YAML::Node frames = r.child(root, "frames", "");
  r.check_keys(frames, "frames", {"crane_from_base", "gravity"});
  model.task_from_base = read_matrix3(r, frames, "crane_from_base", "frames");
  const auto g = r.values(frames, "gravity", "frames", Dimension::kAcceleration, 3);
  model.gravity_m_s2 = Eigen::Vector3d(g[0], g[1], g[2]);
  check_gravity(r, frames["gravity"], "frames.gravity", model.gravity_m_s2, model.task_from_base);

  read_joints(r, root, model);
  read_bodies(r, root, model);
  read_hydraulics(r, root, model);
  read_grapple(r, root, model);

  const YAML::Node control = r.child(root, "control", "");
  r.check_keys(control, "control",
               {"rate", "position_gain", "flow_reserve", "activation_speed", "activation_error",
                "rest_speed", "rest_timeout"});
  cfg.control.rate_hz =
      r.value_in(control, "rate", "control", Dimension::kFrequency, 1.0, 10000.0, "1 to 10000 Hz");
  cfg.control.position_gain_1_s = r.value_in(control, "position_gain", "control",
                                             Dimension::kInverseTime, 0.0, 1000.0, "0 to 1000 1/s");
  cfg.control.flow_reserve = r.value_in(control, "flow_reserve", "control",
                                        Dimension::kDimensionless, 0.0, 0.5, "between 0 and 0.5");
  if (control["activation_speed"].IsDefined()) {
    cfg.control.activation_speed_m_s = r.value_in(control, "activation_speed", "control",
                                                  Dimension::kVelocity, 0.0, 0.1, "0 to 0.1 m/s");
  }
  if (control["activation_error"].IsDefined()) {
    cfg.control.activation_error_m = r.value_in(control, "activation_error", "control",
                                                Dimension::kLength, 0.0, 0.1, "0 to 0.1 m");
  }

  if (control["rest_speed"].IsDefined()) {
    cfg.control.rest_speed_m_s = r.value_in(control, "rest_speed", "control", Dimension::kVelocity,
                                            1e-4, 0.1, "0.1 mm/s to 0.1 m/s");
  }
  if (control["rest_timeout"].IsDefined()) {
    cfg.control.rest_timeout_s =
        r.value_in(control, "rest_timeout", "control", Dimension::kTime, 0.0, 4.0, "0 to 4 s");
  }

  const YAML::Node scaling = r.child(root, "scaling", "");
  const std::string sp = "scaling";
  r.check_keys(scaling, sp,
               {"jerk_max", "acceleration_max", "deceleration_max", "direction_change_acceleration",
                "tracking_error_ok", "tracking_error_filter", "power_bound", "power_reserve",
                "sway_damping", "sway_frequency"});
  auto& sc = cfg.scaling;
  sc.jerk_max_m_s3 =
      r.value_in(scaling, "jerk_max", sp, Dimension::kJerk, 1e-3, 1e4, "between 0.001 and 10000");
  sc.acceleration_max_m_s2 = r.value_in(scaling, "acceleration_max", sp, Dimension::kAcceleration,
                                        1e-3, 100.0, "between 0.001 and 100");
  sc.deceleration_max_m_s2 = r.value_in(scaling, "deceleration_max", sp, Dimension::kAcceleration,
                                        1e-3, 100.0, "between 0.001 and 100");
  sc.direction_change_acceleration_m_s2 =
      r.value_in(scaling, "direction_change_acceleration", sp, Dimension::kAcceleration, 1e-3,
                 100.0, "between 0.001 and 100");
  sc.tracking_error_ok_m = r.value_in(scaling, "tracking_error_ok", sp, Dimension::kLength, 1e-4,
                                      10.0, "between 0.1 mm and 10 m");
  sc.tracking_error_filter_s = r.value_in(scaling, "tracking_error_filter", sp, Dimension::kTime,
                                          0.0, 10.0, "between 0 and 10 s");
  sc.power_reserve = r.value_in(scaling, "power_reserve", sp, Dimension::kDimensionless, 0.0, 0.5,
                                "between 0 and 0.5");
  sc.power_bound = r.one_of(scaling, "power_bound", sp, dynamics::kPowerBounds);
  sc.sway_damping = r.flag(scaling, "sway_damping", sp, true);
  if (scaling["sway_frequency"].IsDefined()) {
    const std::string f = r.text(scaling, "sway_frequency", sp);
    if (f != "model" && f != "measured") {
      r.fail(scaling["sway_frequency"], "scaling.sway_frequency",
             "expected model or measured, got '" + f + "'");
    }
    sc.sway_frequency_measured = f == "measured";
  }

  const YAML::Node redundancy = r.child(root, "redundancy", "");
  r.check_keys(redundancy, "redundancy", {"resolution"});
  const std::string resolution = r.text(redundancy, "resolution", "redundancy");
  try {
    set_resolution(cfg, resolution);
  } catch (const std::invalid_argument& e) {
    r.fail(redundancy["resolution"], "redundancy.resolution", e.what());
  }

  const YAML::Node sim = r.child(root, "simulation", "");
  r.check_keys(sim, "simulation",
               {"step", "initial", "pressure_sensors", "return_pressure", "spool_time_constant",
                "valves", "joint_sensors", "feedback", "swing_sensor", "grapple"});
  cfg.simulation.step_s =
      r.value_in(sim, "step", "simulation", Dimension::kTime, 1e-5, 1e-2, "between 0.01 and 10 ms");
  const double period = 1.0 / cfg.control.rate_hz;
  const double ratio = period / cfg.simulation.step_s;
  if (std::abs(ratio - std::round(ratio)) > 1e-6 * ratio) {
    r.fail(sim["step"], "simulation.step",
           "must divide the control period (" + std::to_string(period * 1e3) + " ms) evenly");
  }
  const YAML::Node initial = r.child(sim, "initial", "simulation");
  if (!initial.IsMap()) r.fail(initial, "simulation.initial", "expected joint: value pairs");
  cfg.simulation.q_initial.resize(model.dof());
  for (int i = 0; i < model.dof(); ++i) {
    const auto& joint = model.joints[i];
    const Dimension qdim =
        joint.type == dynamics::JointType::kRevolute ? Dimension::kAngle : Dimension::kLength;
    const double q = r.value(initial, joint.name, "simulation.initial", qdim);
    if (q < joint.q_min || q > joint.q_max) {
      r.fail(initial[joint.name], "simulation.initial." + joint.name, "outside the joint range");
    }
    cfg.simulation.q_initial[i] = q;
  }
  for (const auto& kv : initial) {
    bool known = false;
    for (const auto& joint : model.joints) known = known || joint.name == kv.first.Scalar();
    if (!known)
      r.fail(kv.first, "simulation.initial." + kv.first.Scalar(), "no joint of that name");
  }
  if (const auto sensors =
          r.optional_section(sim, "pressure_sensors", "simulation", {"noise", "resolution"})) {
    const YAML::Node& ps = *sensors;
    const std::string pp = "simulation.pressure_sensors";
    cfg.simulation.pressure_noise_pa =
        r.value_in(ps, "noise", pp, Dimension::kPressure, 0.0, 1e7, "between 0 and 100 bar");
    cfg.simulation.pressure_resolution_pa =
        r.value_in(ps, "resolution", pp, Dimension::kPressure, 0.0, 1e7, "between 0 and 100 bar");
  }
  if (sim["return_pressure"].IsDefined()) {
    cfg.simulation.return_pressure_pa =
        r.value_in(sim, "return_pressure", "simulation", Dimension::kPressure, 0.0,
                   model.pump.max_pressure_pa, "between 0 and the pump's max_pressure");
  }
  read_simulated_machine(r, sim, "simulation", cfg);
  read_simulated_grapple(r, sim, cfg);
  read_load_chart(r, root, cfg.load_chart);
  read_backend(r, root, cfg.backend);
  cfg.unsourced_quantities = r.unsourced();
  return cfg;
}

}  // namespace

double LoadChart::rated_kg_at(double reach) const {
  if (reach_m.empty() || !std::isfinite(reach)) return 0.0;
  if (reach <= reach_m.front()) return rated_kg.front();
  if (reach >= reach_m.back()) return rated_kg.back() * reach_m.back() / reach;
  std::size_t k = 1;
  while (reach_m[k] < reach) ++k;
  const double w = (reach - reach_m[k - 1]) / (reach_m[k] - reach_m[k - 1]);
  return rated_kg[k - 1] + w * (rated_kg[k] - rated_kg[k - 1]);
}

const char* to_string(BackendKind kind) {
  return kind == BackendKind::kCan ? "can" : "sim";
}

void apply_simulated_machine(const YAML::Node& node, const std::string& source,
                             const std::string& path, CraneConfig& cfg) {
  Reader r{source};
  r.check_keys(node, path, {"spool_time_constant", "valves", "joint_sensors", "feedback"});
  read_simulated_machine(r, node, path, cfg);
}

CraneConfig parse_crane_config(std::string_view yaml_text, std::string_view source_name) {
  Reader reader{std::string(source_name)};
  return read_yaml(yaml_text, source_name,
                   [&](const YAML::Node& root) { return read_config(reader, root, source_name); });
}

CraneConfig load_crane_config(const std::filesystem::path& path) {
  return parse_crane_config(read_yaml_file(path, "crane config"), path.string());
}

CraneConfig default_crane_config() {
  return parse_crane_config(embedded::kK70mYaml, "<embedded config/cranes/k70m.yaml>");
}

CraneConfig planar_2r_config() {
  return parse_crane_config(embedded::kPlanar2rYaml, "<embedded config/cranes/planar_2r.yaml>");
}

CraneConfig mhsb_3link_config() {
  return parse_crane_config(embedded::kMhsb3linkYaml, "<embedded config/cranes/mhsb_3link.yaml>");
}

void apply_energy_optimal(CraneConfig& cfg) {
  if (cfg.redundancy.energy_optimal) {
    cfg.redundancy.resolution = dynamics::energy_optimal_resolution(cfg.model.pump.mode);
  }
}

std::vector<std::string> resolution_names() {
  std::vector<std::string> names = names_of(dynamics::kResolutions);
  names.emplace(names.begin(), kEnergyOptimal);
  return names;
}

void set_resolution(CraneConfig& cfg, std::string_view name) {
  dynamics::Resolution r = dynamics::Resolution::kPinvJoint;
  const bool energy_optimal = name == kEnergyOptimal;
  if (energy_optimal) {
    r = dynamics::energy_optimal_resolution(cfg.model.pump.mode);
  } else if (const auto parsed = dynamics::parse_resolution(name)) {
    r = *parsed;
  } else {
    throw std::invalid_argument("expected " + std::string(kEnergyOptimal) + ", " +
                                alternatives(dynamics::kResolutions) + ", got '" +
                                std::string(name) + "'");
  }
  if (r != dynamics::Resolution::kPinvJoint && !dynamics::is_loader_structure(cfg.model)) {
    throw std::invalid_argument(
        "the resolutions other than pinv-joint need a loader crane (slew, lift, tilt, "
        "extension)");
  }
  cfg.redundancy.resolution = r;
  cfg.redundancy.energy_optimal = energy_optimal;
}

std::string resolution_description(const CraneConfig& cfg) {
  std::string text = dynamics::to_string(cfg.redundancy.resolution);
  if (cfg.redundancy.energy_optimal) {
    text += cfg.model.pump.mode == dynamics::PumpMode::kConstantPressure
                ? " (energy-optimal for a constant-pressure pump)"
                : " (energy-optimal for load sensing)";
  }
  return text;
}

dynamics::JointVector parse_joint_pose(const dynamics::CraneModel& model, std::string_view text,
                                       const dynamics::JointVector& base) {
  if (base.size() != model.dof()) throw std::invalid_argument("pose: base has the wrong size");
  dynamics::JointVector q = base;
  std::vector<bool> given(static_cast<std::size_t>(model.dof()), false);
  std::size_t start = 0;
  bool any = false;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    std::string_view part = text.substr(start, comma - start);
    start = comma + 1;
    while (!part.empty() && std::isspace(static_cast<unsigned char>(part.front()))) {
      part.remove_prefix(1);
    }
    while (!part.empty() && std::isspace(static_cast<unsigned char>(part.back()))) {
      part.remove_suffix(1);
    }
    if (part.empty()) {
      if (comma == text.size()) break;
      throw std::invalid_argument("empty part between commas");
    }
    const std::size_t eq = part.find('=');
    if (eq == std::string_view::npos) {
      throw std::invalid_argument("'" + std::string(part) + "': expected NAME=VALUE UNIT");
    }
    std::string name(part.substr(0, eq));
    while (!name.empty() && std::isspace(static_cast<unsigned char>(name.back()))) name.pop_back();
    const std::string_view value = part.substr(eq + 1);
    int index = -1;
    std::string names;
    for (int i = 0; i < model.dof(); ++i) {
      const auto& joint = model.joints[static_cast<std::size_t>(i)];
      if (joint.name == name) index = i;
      names += (names.empty() ? "" : ", ") + joint.name;
    }
    if (index < 0) {
      throw std::invalid_argument("'" + name + "': no joint of that name (the joints: " + names +
                                  ")");
    }
    if (given[static_cast<std::size_t>(index)]) {
      throw std::invalid_argument("'" + name + "' given twice");
    }
    given[static_cast<std::size_t>(index)] = true;
    const auto& joint = model.joints[static_cast<std::size_t>(index)];
    const Dimension dim =
        joint.type == dynamics::JointType::kRevolute ? Dimension::kAngle : Dimension::kLength;
    std::string error;
    const auto quantity = parse_quantity(value, dim, error);
    if (!quantity || quantity->si_values.size() != 1) {
      throw std::invalid_argument("'" + name +
                                  "': " + (error.empty() ? "expected one value" : error));
    }
    const double v = quantity->si_values[0];
    if (!(v >= joint.q_min && v <= joint.q_max)) {
      std::ostringstream why;
      why << "'" << name << "': outside the joint range [" << joint.q_min << ", " << joint.q_max
          << "] " << (dim == Dimension::kAngle ? "rad" : "m");
      throw std::invalid_argument(why.str());
    }
    q[index] = v;
    any = true;
  }
  if (!any) throw std::invalid_argument("no joint given (expected NAME=VALUE UNIT, ...)");
  return q;
}

namespace {

void check_override(const FieldRange& range, double value) {
  if (!range.contains(value)) throw std::invalid_argument(std::string("must be ") + range.text);
}

}  // namespace

void set_payload_mass(dynamics::CraneModel& model, double mass_kg) {
  check_override(kPayloadMass, mass_kg);
  dynamics::set_payload_mass_kg(model, mass_kg);
}

void set_pump_max_flow(dynamics::CraneModel& model, double m3_s) {
  check_override(kPumpMaxFlow, m3_s);
  model.pump.max_flow_m3_s = m3_s;
}

void set_prime_mover_power(dynamics::CraneModel& model, double w) {
  check_override(kPrimeMoverPower, w);
  model.pump.prime_mover_power_w = w;
}

void set_supply_pressure(dynamics::CraneModel& model, double pa) {
  if (const std::string why = supply_pressure_problem(model.pump, pa); !why.empty()) {
    throw std::invalid_argument(why);
  }
  model.pump.supply_pressure_pa = pa;
}

void set_can_feedback_timeout(BackendSettings& backend, double seconds) {
  check_override(kFeedbackTimeout, seconds);
  backend.can.feedback_timeout_s = seconds;
}

}  // namespace craneassist::config
