#include "scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "craneassist/control/log_fields.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/pendulum.hpp"

namespace craneassist::web {
namespace {

// Appends printf-style text (numbers: %.5g keeps the messages short and exact enough to draw).
template <typename... Args>
void put(std::string& out, const char* fmt, Args... args) {
  char buf[64];
  const int n = std::snprintf(buf, sizeof buf, fmt, args...);
  if (n > 0) out.append(buf, static_cast<std::size_t>(std::min<int>(n, sizeof buf - 1)));
}

// A number for JSON: non-finite values (a sensor that is not there) become null.
void number(std::string& out, double v) {
  if (std::isfinite(v)) {
    put(out, "%.5g", v);
  } else {
    out += "null";
  }
}

void numbers(std::string& out, const double* v, int n) {
  out += '[';
  for (int i = 0; i < n; ++i) {
    if (i > 0) out += ',';
    number(out, v[i]);
  }
  out += ']';
}

// A JSON string from text the project controls (names from the config).
void quoted(std::string& out, std::string_view s) {
  control::append_json_string(s, out);
}

// One JSON object, field by field, appended to a string.
class Object {
 public:
  explicit Object(std::string& out) : out_(out) { out_ += '{'; }
  Object& number(const char* name, double v) {
    key(name);
    web::number(out_, v);
    return *this;
  }
  Object& integer(const char* name, long long v) {
    key(name);
    put(out_, "%lld", v);
    return *this;
  }
  Object& numbers(const char* name, const double* v, int n) {
    key(name);
    web::numbers(out_, v, n);
    return *this;
  }
  Object& vec3(const char* name, const Eigen::Vector3d& v) { return numbers(name, v.data(), 3); }
  Object& text(const char* name, std::string_view s) {
    key(name);
    quoted(out_, s);
    return *this;
  }
  Object& flag(const char* name, bool v) {
    key(name);
    out_ += v ? "true" : "false";
    return *this;
  }
  // A nested value the caller appends next (an object or an array).
  std::string& nested(const char* name) {
    key(name);
    return out_;
  }
  void close() { out_ += '}'; }

 private:
  void key(const char* name) {
    if (!first_) out_ += ',';
    first_ = false;
    quoted(out_, name);
    out_ += ':';
  }
  std::string& out_;
  bool first_ = true;
};

}  // namespace

std::string crane_json(const config::CraneConfig& crane, double frame_rate_hz) {
  const dynamics::CraneModel& m = crane.model;
  std::string out;
  Object root(out);
  root.text("name", m.name);
  std::string& joints = root.nested("joints");
  joints += '[';
  for (std::size_t i = 0; i < m.joints.size(); ++i) {
    if (i > 0) joints += ',';
    const auto& j = m.joints[i];
    Object(joints)
        .text("name", j.name)
        .flag("prismatic", j.type == dynamics::JointType::kPrismatic)
        .number("min", j.q_min)
        .number("max", j.q_max)
        .close();
  }
  joints += ']';
  std::string& cylinders = root.nested("cylinders");
  cylinders += '[';
  for (std::size_t i = 0; i < m.cylinders.size(); ++i) {
    if (i > 0) cylinders += ',';
    Object(cylinders)
        .text("name", m.cylinders[i].name)
        .number("bore_m", 2.0 * std::sqrt(m.cylinders[i].area_a_m2 / M_PI))
        .close();
  }
  cylinders += ']';
  Object(root.nested("pump"))
      .number("max_flow_m3s", m.pump.max_flow_m3_s)
      .number("max_pressure_pa", dynamics::supply_pressure_ceiling_pa(m.pump))
      .number("max_power_w", m.pump.prime_mover_power_w)
      .close();
  // The field table (control/log_fields.hpp): the page lists every value of frame.fields by it.
  std::string& fields = root.nested("fields");
  fields += '[';
  for (const control::Field& field : control::field_table()) {
    if (fields.back() != '[') fields += ',';
    Object(fields)
        .text("name", field.name)
        .text("unit", field.unit)
        .text("group", control::to_string(field.group))
        .text("meaning", field.meaning)
        .close();
  }
  fields += ']';
  root.number("rate_hz", crane.control.rate_hz).number("frame_rate_hz", frame_rate_hz).close();
  return out;
}

SceneBuilder::SceneBuilder(const dynamics::CraneModel& model, const dynamics::MobileBaseModel* base)
    : model_(model), base_(base) {}

namespace {

// A 3x3 matrix row by row.
void matrix(std::string& out, const Eigen::Matrix3d& m) {
  const double v[9] = {m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1),
                       m(1, 2), m(2, 0), m(2, 1), m(2, 2)};
  numbers(out, v, 9);
}

Eigen::Matrix3d yaw(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

void SceneBuilder::base_json(const control::LogRow& row, std::string& out) const {
  Object b(out);
  b.numbers("pose", row.base_pose.data(), 3)
      .numbers("velocity", row.base_velocity.data(), 2)
      .numbers("command", row.base_command.data(), 2)
      .numbers("motor_flow", row.base_motor_flow.data(), 4)
      .number("flow_sum", row.base_flow_sum_m3s)
      .number("flow_max", row.base_flow_max_m3s)
      .flag("shared_pump", row.base_shared_pump);
  if (base_ == nullptr) {
    b.close();
    return;
  }
  // The view's frame is the crane frame of a fixed crane (y up): the world (z up) is drawn
  // through the same turn, task_from_base. The crane's root: its frame in the view's.
  const Eigen::Matrix3d& t = model_.task_from_base;
  const dynamics::BasePose pose{row.base_pose[0], row.base_pose[1], row.base_pose[2]};
  const Eigen::Vector3d mount =
      dynamics::world_from_crane_base(*base_, pose, Eigen::Vector3d::Zero());
  matrix(b.nested("root_r"), t * yaw(pose.phi_rad + base_->crane_mount_yaw_rad) * t.transpose());
  b.vec3("root_p", t * mount);
  // Boxes in world axes (x along the heading, z up), placed: r maps the box's axes to the
  // view's, p its centre, size its extent along its axes.
  std::string& boxes = b.nested("boxes");
  boxes += '[';
  auto box = [&](const char* kind, const Eigen::Matrix3d& r_world, const Eigen::Vector3d& p_world,
                 const Eigen::Vector3d& size) {
    if (boxes.back() != '[') boxes += ',';
    Object o(boxes);
    o.text("kind", kind);
    matrix(o.nested("r"), t * r_world);
    o.vec3("p", t * p_world).vec3("size", size).close();
  };
  const double r_wheel = base_->wheel_radius_m;
  const Eigen::Matrix3d r_chassis = yaw(pose.phi_rad);
  const Eigen::Vector3d xy(pose.x_m, pose.y_m, 0.0);
  box("chassis", r_chassis, xy + Eigen::Vector3d(0.0, 0.0, r_wheel + 0.15),
      Eigen::Vector3d(2.0 * base_->half_length_m, 2.0 * (base_->half_width_m - 0.1), 0.3));
  dynamics::WheelState wheels;
  dynamics::wheel_inverse_kinematics(*base_, row.base_velocity[1], row.base_velocity[0], wheels);
  for (int i = 0; i < dynamics::kBaseWheels; ++i) {
    const double steer = wheels.steer_rad[static_cast<std::size_t>(i)];
    const Eigen::Vector2d c = dynamics::wheel_centre(*base_, i, steer);
    box("wheel", yaw(pose.phi_rad + steer), xy + r_chassis * Eigen::Vector3d(c.x(), c.y(), r_wheel),
        Eigen::Vector3d(2.0 * r_wheel, 0.3, 2.0 * r_wheel));
  }
  boxes += ']';
  b.close();
}

void SceneBuilder::frame_json(const control::LogRow& row, std::uint64_t seq, std::string& out) {
  const int n = model_.dof();
  out.clear();
  Object f(out);
  f.text("type", "frame")
      .integer("seq", static_cast<long long>(seq))
      .number("t", row.t)
      .text("status", row.status)
      .text("stop_reason", row.stop_reason)
      .text("input", row.input_source)
      .flag("deadman", row.deadman)
      .text("limit", row.active_limit)
      .text("pump_limit", row.pump_limit)
      .number("scale", row.scale)
      .number("sdot", row.sdot)
      .numbers("cmd", row.cmd.data(), 3)
      .numbers("ref", row.ref_v.data(), 3)
      .numbers("tip", row.tip.data(), 3)
      .numbers("tip_v", row.tip_v.data(), 3)
      .numbers("q", row.q.data(), n)
      .numbers("p_load", row.load_pressure.data(), n)
      .numbers("spool", row.spool.data(), n);
  Object(f.nested("pump"))
      .number("flow", row.pump_flow_m3s)
      .number("pressure", row.pump_pressure_pa)
      .number("power", row.pump_power_w)
      .number("energy", row.energy_j)
      .close();
  // The flow manipulability polytope: the fastest tip speed along the stick's direction (the
  // last one while the stick is released) and along the chosen joint motion, m/s; its dimension
  // and its measure in that dimension (volume m^3/s^3, or a flat one's area m^2/s^2).
  f.number("avail", row.avail_speed_m_s).number("avail_resolved", row.avail_speed_resolved_m_s);
  Object(f.nested("polytope"))
      .integer("dim", row.polytope_dim)
      .number("volume", row.polytope_volume_m3s3)
      .number("area", row.polytope_area_m2s2)
      .close();
  // The load (docs/loads.md): the crane scale, the load moment against the chart, the limiter;
  // truth is the simulated load (null on a machine).
  Object(f.nested("load"))
      .number("estimate", row.payload_estimate_kg)
      .flag("converged", row.payload_converged)
      .number("ratio", row.load_moment_ratio)
      .number("rated", row.rated_load_kg)
      .number("reach", row.load_reach_m)
      .flag("warning", row.load_warning)
      .flag("overload", row.load_overload)
      .number("truth", row.load_kg)
      .close();
  // The hanging grapple (docs/sway.md): its swing in degrees (from the vertical, towards the reach,
  // across it; null where nothing measures it) and where its centre of mass hangs (crane frame).
  if (model_.grapple.hangs()) {
    constexpr double kDeg = 180.0 / M_PI;
    const Eigen::Matrix3d& t = model_.task_from_base;
    const Eigen::Vector3d tip(row.tip[0], row.tip[1], row.tip[2]);
    const Eigen::Vector3d at =
        t * dynamics::grapple_position(model_, t.transpose() * tip, row.swing_radial_rad,
                                       row.swing_tangential_rad);
    Object(f.nested("grapple"))
        .number("swing", row.swing_rad * kDeg)
        .number("radial", row.swing_radial_rad * kDeg)
        .number("tangential", row.swing_tangential_rad * kDeg)
        .vec3("at", at)
        .close();
  }
  if (row.base_present) base_json(row, f.nested("base"));
  // Every value of the field table, by group (the page's "All values" list).
  std::string& fields = f.nested("fields");
  fields += '{';
  for (const control::FieldGroup g : control::kFieldGroups) {
    if (g == control::FieldGroup::kBase && !row.base_present) continue;
    if (fields.back() != '{') fields += ',';
    fields += '"';
    fields += control::to_string(g);
    fields += "\":";
    control::append_group_json(row, n, g, fields);
  }
  fields += '}';

  // The drawing: joint frame origins, and each cylinder's ends.
  dynamics::JointVector q(n);
  bool finite = true;
  for (int i = 0; i < n; ++i) {
    q[i] = row.q[static_cast<std::size_t>(i)];
    finite = finite && std::isfinite(q[i]);
  }
  if (!finite) {
    f.nested("points") += "null";
    f.nested("cylinders") += "null";
    f.close();
    return;
  }
  dynamics::forward_kinematics(model_, data_, q);
  const Eigen::Matrix3d& r = model_.task_from_base;
  std::string& points = f.nested("points");
  points += '[';
  for (int i = 0; i <= n; ++i) {
    if (i > 0) points += ',';
    const Eigen::Vector3d p = r * data_.frames[static_cast<std::size_t>(i)].translation();
    numbers(points, p.data(), 3);
  }
  points += ']';
  std::string& cylinders = f.nested("cylinders");
  cylinders += '[';
  for (int i = 0; i < n; ++i) {
    const auto& c = model_.cylinders[static_cast<std::size_t>(i)];
    const auto k = static_cast<std::size_t>(i);
    // Joint i turns (or slides) about the z axis of frame i-1, at its origin.
    const Eigen::Vector3d o = data_.frames[k].translation();
    const Eigen::Vector3d z = data_.frames[k].linear().col(2);
    const Eigen::Vector3d x = data_.frames[k + 1].linear().col(0);  // along the moving link
    Eigen::Vector3d a, b;
    if (c.linkage == dynamics::LinkageType::kTriangle) {
      // One end on the moving link at l2, the other fixed to the previous link at l1, the angle
      // between them q + offset: |a - b| is the cylinder length of the model.
      const double phi = q[i] + c.angle_offset_rad;
      b = o + c.l2_m * x;
      a = o + c.l1_m * Eigen::AngleAxisd(-phi, z).toRotationMatrix() * x;
    } else if (model_.joints[k].type == dynamics::JointType::kPrismatic) {
      // The extension cylinder lies along the sliding link, from the joint's origin.
      a = o;
      b = o + dynamics::cylinder_length(c, q[i]) * z;
    } else if (i > 0) {
      // Another linkage (a four-bar fit): a sketch across the joint, from the previous link to
      // the moving one, both arms L, with the model's length at mid-range. Its length follows
      // the joint angle, not the fit.
      const auto& j = model_.joints[k];
      const double q_mid = 0.5 * (j.q_min + j.q_max);
      const double spread = std::sqrt(2.0 * (1.0 + std::cos(q_mid + j.theta_rad)));
      const double arm =
          std::clamp(dynamics::cylinder_length(c, q_mid) / std::max(spread, 0.2), 0.3, 2.0);
      const Eigen::Vector3d x_prev = data_.frames[k].linear().col(0);
      a = o - arm * x_prev;
      b = o + arm * x;
    } else {
      continue;  // the slew drive: drawn as the pillar, its pressure in the gauges
    }
    if (cylinders.back() != '[') cylinders += ',';
    Object(cylinders).integer("joint", i).vec3("a", r * a).vec3("b", r * b).close();
  }
  cylinders += ']';
  f.close();
}

}  // namespace craneassist::web
