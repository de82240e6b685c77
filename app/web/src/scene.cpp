#include "scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "craneassist/dynamics/cylinders.hpp"

namespace craneassist::web {
namespace {

// Appends printf-style text (numbers: %.4g keeps the messages short and exact enough to draw).
template <typename... Args>
void put(std::string& out, const char* fmt, Args... args) {
  char buf[256];
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

void vec3(std::string& out, const Eigen::Vector3d& v) {
  out += '[';
  number(out, v.x());
  out += ',';
  number(out, v.y());
  out += ',';
  number(out, v.z());
  out += ']';
}

void array(std::string& out, const double* v, int n) {
  out += '[';
  for (int i = 0; i < n; ++i) {
    if (i > 0) out += ',';
    number(out, v[i]);
  }
  out += ']';
}

// A JSON string from text the project controls (names from the config): quotes and control
// characters escaped.
void string(std::string& out, const std::string& s) {
  out += '"';
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      put(out, "\\u%04x", static_cast<unsigned>(c));
    } else {
      out += c;
    }
  }
  out += '"';
}

}  // namespace

std::string crane_json(const config::CraneConfig& crane, double frame_rate_hz) {
  const dynamics::CraneModel& m = crane.model;
  std::string out = "{\"name\":";
  string(out, m.name);
  out += ",\"joints\":[";
  for (int i = 0; i < m.dof(); ++i) {
    const auto& j = m.joints[static_cast<std::size_t>(i)];
    if (i > 0) out += ',';
    out += "{\"name\":";
    string(out, j.name);
    put(out,
        ",\"prismatic\":%s,\"min\":", j.type == dynamics::JointType::kPrismatic ? "true" : "false");
    number(out, j.q_min);
    out += ",\"max\":";
    number(out, j.q_max);
    out += '}';
  }
  out += "],\"cylinders\":[";
  for (std::size_t i = 0; i < m.cylinders.size(); ++i) {
    if (i > 0) out += ',';
    out += "{\"name\":";
    string(out, m.cylinders[i].name);
    out += ",\"bore_m\":";
    number(out, 2.0 * std::sqrt(m.cylinders[i].area_a_m2 / M_PI));
    out += '}';
  }
  out += "],\"pump\":{\"max_flow_m3s\":";
  number(out, m.pump.max_flow_m3_s);
  out += ",\"max_pressure_pa\":";
  number(out, dynamics::supply_pressure_ceiling_pa(m.pump));
  out += ",\"max_power_w\":";
  number(out, m.pump.prime_mover_power_w);
  out += "},\"rate_hz\":";
  number(out, crane.control.rate_hz);
  out += ",\"frame_rate_hz\":";
  number(out, frame_rate_hz);
  out += '}';
  return out;
}

SceneBuilder::SceneBuilder(const dynamics::CraneModel& model) : model_(model) {}

void SceneBuilder::frame_json(const control::LogRow& row, std::uint64_t seq, std::string& out) {
  const int n = model_.dof();
  out.clear();
  put(out, "{\"type\":\"frame\",\"seq\":%llu,\"t\":", static_cast<unsigned long long>(seq));
  number(out, row.t);
  out += ",\"status\":";
  string(out, row.status);
  out += ",\"stop_reason\":";
  string(out, row.stop_reason);
  out += ",\"input\":";
  string(out, row.input_source);
  put(out, ",\"deadman\":%s,\"limit\":", row.deadman ? "true" : "false");
  string(out, row.active_limit);
  out += ",\"pump_limit\":";
  string(out, row.pump_limit);
  out += ",\"scale\":";
  number(out, row.scale);
  out += ",\"sdot\":";
  number(out, row.sdot);
  out += ",\"cmd\":";
  array(out, row.cmd.data(), 3);
  out += ",\"ref\":";
  array(out, row.ref_v.data(), 3);
  out += ",\"tip\":";
  array(out, row.tip.data(), 3);
  out += ",\"tip_v\":";
  array(out, row.tip_v.data(), 3);
  out += ",\"q\":";
  array(out, row.q.data(), n);
  out += ",\"p_load\":";
  array(out, row.load_pressure.data(), n);
  out += ",\"spool\":";
  array(out, row.spool.data(), n);
  out += ",\"pump\":{\"flow\":";
  number(out, row.pump_flow_m3s);
  out += ",\"pressure\":";
  number(out, row.pump_pressure_pa);
  out += ",\"power\":";
  number(out, row.pump_power_w);
  out += ",\"energy\":";
  number(out, row.energy_j);
  out += '}';

  // The drawing: joint frame origins, and each cylinder's ends.
  dynamics::JointVector q(n);
  bool finite = true;
  for (int i = 0; i < n; ++i) {
    q[i] = row.q[static_cast<std::size_t>(i)];
    finite = finite && std::isfinite(q[i]);
  }
  if (!finite) {
    out += ",\"points\":null,\"cylinders\":null}";
    return;
  }
  dynamics::forward_kinematics(model_, data_, q);
  const Eigen::Matrix3d& r = model_.task_from_base;
  out += ",\"points\":[";
  for (int i = 0; i <= n; ++i) {
    if (i > 0) out += ',';
    vec3(out, r * data_.frames[static_cast<std::size_t>(i)].translation());
  }
  out += "],\"cylinders\":[";
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
    if (i > 0 && out.back() != '[') out += ',';
    put(out, "{\"joint\":%d,\"a\":", i);
    vec3(out, r * a);
    out += ",\"b\":";
    vec3(out, r * b);
    out += '}';
  }
  out += "]}";
}

}  // namespace craneassist::web
