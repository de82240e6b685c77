#include "craneassist/dynamics/urdf.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/pendulum.hpp"

namespace craneassist::dynamics {
namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", std::abs(v) < 1e-12 ? 0.0 : v);  // exact
  return buf;
}

std::string xyz(const Eigen::Vector3d& v) {
  return num(v.x()) + " " + num(v.y()) + " " + num(v.z());
}

// URDF's rpy: fixed-axis roll (x), pitch (y), yaw (z), R = Rz(yaw) Ry(pitch) Rx(roll).
std::string rpy(const Eigen::Matrix3d& r) {
  const double roll = std::atan2(r(2, 1), r(2, 2));
  const double pitch = std::atan2(-r(2, 0), std::hypot(r(2, 1), r(2, 2)));
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  return num(roll) + " " + num(pitch) + " " + num(yaw);
}

std::string origin(const Eigen::Isometry3d& t) {
  return "<origin xyz=\"" + xyz(t.translation()) + "\" rpy=\"" + rpy(t.linear()) + "\"/>";
}

// A box (or the pillar's cylinder) from the link's origin to `end`, in the link's frame.
std::string visual(const Eigen::Vector3d& end, bool pillar) {
  const double len = end.norm();
  if (len < 1e-3) return {};
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = 0.5 * end;
  t.linear() =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), end / len).toRotationMatrix();
  const std::string geometry = pillar ? "<cylinder radius=\"0.12\" length=\"" + num(len) + "\"/>"
                                      : "<box size=\"0.14 0.14 " + num(len) + "\"/>";
  return "    <visual>\n      " + origin(t) + "\n      <geometry>" + geometry +
         "</geometry>\n      <material name=\"" + std::string(pillar ? "dark" : "boom") +
         "\"/>\n    </visual>\n";
}

struct Inertial {
  double mass = 0.0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about com, in the link's axes
};

// A body in a link's frame: its mass at com with its inertia (about com) in the link's axes.
struct PlacedBody {
  double mass = 0.0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

Inertial combine(const std::vector<PlacedBody>& bodies) {
  Inertial out;
  for (const PlacedBody& b : bodies) {
    out.mass += b.mass;
    out.com += b.mass * b.com;
  }
  if (out.mass <= 0.0) return out;
  out.com /= out.mass;
  for (const PlacedBody& b : bodies) {
    const Eigen::Vector3d c = b.com - out.com;
    out.inertia +=
        b.inertia + b.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  }
  return out;
}

// The grapple hangs from the tip, so the bodies at the tip point (the grapple, rotator and
// payload) are grapple_link's, not the last boom link's.
bool hangs_from_tip(const CraneModel& model, const Body& b) {
  return model.grapple.hangs() && b.frame == model.dof() && b.com_m.norm() < kAtTipM;
}

// The bodies on one DH frame (but those that hang from the tip), moved into a link frame by
// `link_from_frame`, combined.
Inertial combine(const CraneModel& model, int frame, const Eigen::Isometry3d& link_from_frame) {
  std::vector<PlacedBody> placed;
  const Eigen::Matrix3d r = link_from_frame.linear();
  for (const Body& b : model.bodies) {
    if (b.frame != frame || b.mass_kg <= 0.0 || hangs_from_tip(model, b)) continue;
    placed.push_back({b.mass_kg, link_from_frame * b.com_m,
                      r * b.inertia_diag_kgm2.asDiagonal() * r.transpose()});
  }
  return combine(placed);
}

// grapple_link's bodies, in its frame (the grapple hangs along axes.hang): the grapple and
// rotator com_below_m down the hanger, the payload load_below_m (a point).
Inertial grapple_inertial(const CraneModel& model, const HangerAxes& axes) {
  std::vector<PlacedBody> placed;
  for (const Body& b : model.bodies) {
    if (!hangs_from_tip(model, b) || b.mass_kg <= 0.0) continue;
    const bool payload = is_payload(b);
    const double depth = payload ? model.grapple.load_below_m : model.grapple.com_below_m;
    // The bodies' inertia diagonal is in the tip frame's axes, as the simulator takes it.
    placed.push_back(
        {b.mass_kg, depth * axes.hang,
         payload ? Eigen::Matrix3d::Zero() : Eigen::Matrix3d(b.inertia_diag_kgm2.asDiagonal())});
  }
  return combine(placed);
}

std::string inertial(const Inertial& in) {
  if (in.mass <= 0.0) {
    // A massless link: a tiny inertial keeps every URDF consumer (and Gazebo) content.
    return "    <inertial><mass value=\"0.001\"/><inertia ixx=\"1e-6\" ixy=\"0\" ixz=\"0\" "
           "iyy=\"1e-6\" iyz=\"0\" izz=\"1e-6\"/></inertial>\n";
  }
  const Eigen::Matrix3d& i = in.inertia;
  return "    <inertial>\n      <origin xyz=\"" + xyz(in.com) + "\" rpy=\"0 0 0\"/>\n" +
         "      <mass value=\"" + num(in.mass) + "\"/>\n      <inertia ixx=\"" + num(i(0, 0)) +
         "\" ixy=\"" + num(i(0, 1)) + "\" ixz=\"" + num(i(0, 2)) + "\" iyy=\"" + num(i(1, 1)) +
         "\" iyz=\"" + num(i(1, 2)) + "\" izz=\"" + num(i(2, 2)) + "\"/>\n    </inertial>\n";
}

// A box of `size` centred at `centre` with its z axis along `z` (unit), in a link's frame.
std::string box_visual(const Eigen::Vector3d& centre, const Eigen::Vector3d& z,
                       const std::string& size, const char* material) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = centre;
  t.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), z).toRotationMatrix();
  return "    <visual>\n      " + origin(t) + "\n      <geometry><box size=\"" + size +
         "\"/></geometry>\n      <material name=\"" + material + "\"/>\n    </visual>\n";
}

// The hanger's two joints and links below tip_link.
std::string hanger_urdf(const CraneModel& model) {
  const HangerAxes axes = hanger_axes(model);
  const double below = model.grapple.com_below_m;
  const auto joint = [](const char* name, const char* parent, const char* child,
                        const Eigen::Vector3d& axis) {
    return std::string("  <joint name=\"") + name + "\" type=\"revolute\">\n    <parent link=\"" +
           parent + "\"/>\n    <child link=\"" + child +
           "\"/>\n    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n    <axis xyz=\"" + xyz(axis) +
           "\"/>\n    <limit lower=\"" + num(-M_PI) + "\" upper=\"" + num(M_PI) +
           "\" velocity=\"100\" effort=\"0\"/>\n  </joint>\n";
  };
  return "  <link name=\"hanger_link\">\n" + inertial(Inertial{}) + "  </link>\n" +
         joint(kHangerJointNames[0], "tip_link", "hanger_link", axes.across) +
         "  <link name=\"grapple_link\">\n" +
         box_visual(0.5 * below * axes.hang, axes.hang, "0.06 0.06 " + num(below), "dark") +
         box_visual(below * axes.hang, axes.hang, "0.5 0.25 0.5", "boom") +
         inertial(grapple_inertial(model, axes)) + "  </link>\n" +
         joint(kHangerJointNames[1], "hanger_link", "grapple_link", axes.along);
}

}  // namespace

HangerAxes hanger_axes(const CraneModel& model) {
  HangerAxes axes;
  const int n = model.dof();
  if (n < 2) return axes;
  JointVector q(n);
  for (int i = 0; i < n; ++i) {
    const auto& j = model.joints[static_cast<std::size_t>(i)];
    q[i] = 0.5 * (j.q_min + j.q_max);
  }
  KinematicsData kin;
  forward_kinematics(model, kin, q);
  const Eigen::Matrix3d tip_from_base =
      kin.frames[static_cast<std::size_t>(n)].linear().transpose();
  axes.across = (tip_from_base * kin.frames[1].linear().col(2)).normalized();
  Eigen::Vector3d hang = tip_from_base * down_direction(model);
  hang -= hang.dot(axes.across) * axes.across;
  axes.hang =
      hang.norm() > 1e-9 ? Eigen::Vector3d(hang.normalized()) : axes.across.unitOrthogonal();
  axes.along = axes.across.cross(axes.hang);
  return axes;
}

std::array<double, 2> hanger_joint_angles(const CraneModel& model, const HangerAxes& axes,
                                          const Eigen::Isometry3d& tip, double radial_rad,
                                          double tangential_rad) noexcept {
  const bool measured = std::isfinite(radial_rad) && std::isfinite(tangential_rad);
  // The hanging direction, base frame (as grapple_position), then in the tip frame.
  const Eigen::Vector3d base_hang =
      (grapple_position(model, tip.translation(), measured ? radial_rad : 0.0,
                        measured ? tangential_rad : 0.0) -
       tip.translation())
          .normalized();
  const Eigen::Vector3d h = tip.linear().transpose() * base_hang;
  // h = Rot(across, a1) Rot(along, a2) hang = cos a2 (cos a1 hang + sin a1 along) - sin a2 across.
  return {std::atan2(h.dot(axes.along), h.dot(axes.hang)),
          -std::asin(std::clamp(h.dot(axes.across), -1.0, 1.0))};
}

std::vector<UrdfFrame> urdf_frames(const CraneModel& model) {
  std::vector<UrdfFrame> frames;
  const int n = model.dof();
  for (int i = 0; i < n; ++i) {
    frames.push_back(
        {i == 0 ? "base_link" : model.joints[static_cast<std::size_t>(i - 1)].name + "_link",
         model.joints[static_cast<std::size_t>(i)].name + "_link"});
  }
  if (n > 0)
    frames.push_back({model.joints[static_cast<std::size_t>(n - 1)].name + "_link", "tip_link"});
  if (n > 0 && model.grapple.hangs()) {
    frames.push_back({"tip_link", "hanger_link"});
    frames.push_back({"hanger_link", "grapple_link"});
  }
  return frames;
}

void urdf_transforms(const CraneModel& model, const HangerAxes& axes, const double* q,
                     const std::array<double, 2>& hanger, Eigen::Isometry3d* out) noexcept {
  const int n = model.dof();
  if (n == 0) return;
  // As to_urdf(): joint i's origin is the fixed part of DH transform i-1, its motion about (or
  // along) its z axis.
  const auto fixed = [&](int i) {
    return dh_transform(model.joints[static_cast<std::size_t>(i)], 0.0);
  };
  for (int i = 0; i < n; ++i) {
    const auto& j = model.joints[static_cast<std::size_t>(i)];
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    if (j.type == JointType::kPrismatic) {
      motion.translation() = Eigen::Vector3d(0.0, 0.0, q[i]);
    } else {
      motion.linear() = Eigen::AngleAxisd(q[i], Eigen::Vector3d::UnitZ()).toRotationMatrix();
    }
    out[i] = (i == 0 ? Eigen::Isometry3d::Identity() : fixed(i - 1)) * motion;
  }
  out[n] = fixed(n - 1);
  if (model.grapple.hangs()) {
    out[n + 1] = Eigen::Isometry3d(Eigen::AngleAxisd(hanger[0], axes.across));
    out[n + 2] = Eigen::Isometry3d(Eigen::AngleAxisd(hanger[1], axes.along));
  }
}

std::string to_urdf(const CraneModel& model, const std::string& robot_name) {
  const int n = model.dof();
  std::string out = "<?xml version=\"1.0\"?>\n<!-- " + model.name +
                    ": generated by craneassist urdf from the crane config (docs/ros.md). -->\n"
                    "<robot name=\"" +
                    robot_name +
                    "\">\n"
                    "  <material name=\"boom\"><color rgba=\"0.85 0.63 0.13 1\"/></material>\n"
                    "  <material name=\"dark\"><color rgba=\"0.23 0.25 0.28 1\"/></material>\n";
  // base_link is DH frame 0; link i carries DH frame i+1 = link frame * dh(joint i, 0).
  auto fixed = [&](int i) { return dh_transform(model.joints[static_cast<std::size_t>(i)], 0.0); };
  out += "  <link name=\"base_link\">\n" +
         inertial(combine(model, 0, Eigen::Isometry3d::Identity())) + "  </link>\n";
  for (int i = 0; i < n; ++i) {
    const auto& j = model.joints[static_cast<std::size_t>(i)];
    const auto& c = model.cylinders[static_cast<std::size_t>(i)];
    const std::string parent = i == 0 ? "base_link" : model.joints[i - 1].name + "_link";
    const Eigen::Isometry3d joint_origin = i == 0 ? Eigen::Isometry3d::Identity() : fixed(i - 1);
    const Eigen::Isometry3d frame = fixed(i);  // DH frame i+1 in this link's frame
    out += "  <link name=\"" + j.name + "_link\">\n" + visual(frame.translation(), i == 0) +
           inertial(combine(model, i + 1, frame)) + "  </link>\n";
    const double mid = 0.5 * (j.q_min + j.q_max);
    const double arm = std::max(std::abs(cylinder_arm(c, mid)), 1e-6);
    const double velocity = c.v_max_m_s > 0.0 ? c.v_max_m_s / arm : 1.0;
    const double effort = c.area_a_m2 * supply_pressure_ceiling_pa(model.pump) * arm;
    const bool prismatic = j.type == JointType::kPrismatic;
    out += "  <joint name=\"" + j.name + "\" type=\"" + (prismatic ? "prismatic" : "revolute") +
           "\">\n    <parent link=\"" + parent + "\"/>\n    <child link=\"" + j.name +
           "_link\"/>\n    " + origin(joint_origin) +
           "\n    <axis xyz=\"0 0 1\"/>\n    <limit lower=\"" + num(j.q_min) + "\" upper=\"" +
           num(j.q_max) + "\" velocity=\"" + num(velocity) + "\" effort=\"" + num(effort) +
           "\"/>\n  </joint>\n";
  }
  out += "  <link name=\"tip_link\"/>\n  <joint name=\"tip\" type=\"fixed\">\n    <parent link=\"" +
         model.joints[static_cast<std::size_t>(n - 1)].name +
         "_link\"/>\n    <child link=\"tip_link\"/>\n    " + origin(fixed(n - 1)) +
         "\n  </joint>\n";
  if (model.grapple.hangs()) out += hanger_urdf(model);
  return out + "</robot>\n";
}

}  // namespace craneassist::dynamics
