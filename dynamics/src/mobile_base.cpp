#include "craneassist/dynamics/mobile_base.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace craneassist::dynamics {
namespace {

bool is_front(int wheel) {
  return wheel < 2;
}
bool is_left(int wheel) {
  return wheel % 2 == 0;
}

// The outboard axle direction of a wheel steered by psi (left wheels: +y turned by psi).
Eigen::Vector2d outboard(int wheel, double psi) {
  const Eigen::Vector2d left(-std::sin(psi), std::cos(psi));
  return is_left(wheel) ? left : Eigen::Vector2d(-left);
}

}  // namespace

const char* wheel_name(int wheel) {
  static constexpr const char* kNames[kBaseWheels] = {"front left", "front right", "rear left",
                                                      "rear right"};
  return wheel >= 0 && wheel < kBaseWheels ? kNames[wheel] : "?";
}

Eigen::Vector2d steering_pivot(const MobileBaseModel& model, int wheel) noexcept {
  return {is_front(wheel) ? model.half_length_m : -model.half_length_m,
          is_left(wheel) ? model.half_width_m : -model.half_width_m};
}

Eigen::Vector2d wheel_centre(const MobileBaseModel& model, int wheel, double steer_rad) noexcept {
  return steering_pivot(model, wheel) + model.wheel_offset_m * outboard(wheel, steer_rad);
}

void wheel_inverse_kinematics(const MobileBaseModel& model, double omega_rad_s, double v_m_s,
                              WheelState& out) noexcept {
  out.flow_sum_m3_s = 0.0;
  out.steer_limited = false;
  const double rev_per_rad = 1.0 / (2.0 * std::numbers::pi);
  for (int i = 0; i < kBaseWheels; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const Eigen::Vector2d l = steering_pivot(model, i);
    // Eq. 2: the pivot's velocity; eq. 3: the steering angle that rolls the wheel along it.
    const double vsx = v_m_s - omega_rad_s * l.y();
    const double vsy = omega_rad_s * l.x();
    double psi = 0.0;
    if (vsx != 0.0) {
      psi = std::atan(vsy / vsx);
    } else if (vsy != 0.0) {
      psi = std::copysign(0.5 * std::numbers::pi, vsy);
    }
    // Eq. 4: the wheel centre, d outboard along the axle, moves with the chassis point there.
    const Eigen::Vector2d c = wheel_centre(model, i, psi);
    const Eigen::Vector2d vm(v_m_s - omega_rad_s * c.y(), omega_rad_s * c.x());
    const Eigen::Vector2d heading(std::cos(psi), std::sin(psi));
    // Eq. 5: signed along the heading (the paper's sign(v_d) |v_m|; the lateral part is zero).
    const double speed = vm.dot(heading);
    const double motor = speed / model.wheel_radius_m * model.gear_ratio;
    out.steer_rad[k] = psi;
    out.speed_m_s[k] = speed;
    out.motor_speed_rad_s[k] = motor;
    out.flow_m3_s[k] = std::abs(motor) * rev_per_rad * model.motor_displacement_m3;
    out.flow_sum_m3_s += out.flow_m3_s[k];
    out.steer_limited = out.steer_limited || std::abs(psi) > model.steer_max_rad + 1e-12;
  }
}

double max_curvature_1_m(const MobileBaseModel& model) noexcept {
  const double r = model.half_length_m / std::tan(model.steer_max_rad) + model.half_width_m;
  return 1.0 / r;
}

double min_outer_turning_radius_m(const MobileBaseModel& model) noexcept {
  const double r_icr = 1.0 / max_curvature_1_m(model);
  const double dy = r_icr + model.half_width_m;
  return std::hypot(model.half_length_m, dy) + model.wheel_offset_m;
}

double limit_yaw_rate(const MobileBaseModel& model, double v_m_s, double omega_rad_s) noexcept {
  const double cap = max_curvature_1_m(model) * std::abs(v_m_s);
  return std::clamp(omega_rad_s, -cap, cap);
}

double flow_per_speed_m2(const MobileBaseModel& model, double curvature_1_m) noexcept {
  WheelState w;
  wheel_inverse_kinematics(model, curvature_1_m, 1.0, w);
  return w.flow_sum_m3_s;
}

double motor_speed_per_speed_1_m(const MobileBaseModel& model, double curvature_1_m) noexcept {
  WheelState w;
  wheel_inverse_kinematics(model, curvature_1_m, 1.0, w);
  double highest = 0.0;
  for (const double n : w.motor_speed_rad_s) highest = std::max(highest, std::abs(n));
  return highest;
}

BasePose integrate_pose(const BasePose& pose, double v_m_s, double omega_rad_s,
                        double dt_s) noexcept {
  const double dphi = omega_rad_s * dt_s;
  // Chord of the arc: length v dt sinc(dphi/2), along the mid-step heading.
  const double half = 0.5 * dphi;
  const double sinc = std::abs(half) < 1e-9 ? 1.0 - half * half / 6.0 : std::sin(half) / half;
  const double chord = v_m_s * dt_s * sinc;
  const double mid = pose.phi_rad + half;
  return {pose.x_m + chord * std::cos(mid), pose.y_m + chord * std::sin(mid), pose.phi_rad + dphi};
}

BaseVelocity lag_velocity(const MobileBaseModel& model, const BaseVelocity& current,
                          const BaseVelocity& command, double dt_s) noexcept {
  const double a =
      model.time_constant_s > 0.0 ? 1.0 - std::exp(-dt_s / model.time_constant_s) : 1.0;
  return {current.v_m_s + a * (command.v_m_s - current.v_m_s),
          current.omega_rad_s + a * (command.omega_rad_s - current.omega_rad_s)};
}

Eigen::Vector3d world_from_crane_base(const MobileBaseModel& model, const BasePose& pose,
                                      const Eigen::Vector3d& p) noexcept {
  const double c = std::cos(pose.phi_rad), s = std::sin(pose.phi_rad);
  const double yaw = pose.phi_rad + model.crane_mount_yaw_rad;
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  const Eigen::Vector3d& m = model.crane_mount_m;
  return {pose.x_m + c * m.x() - s * m.y() + cy * p.x() - sy * p.y(),
          pose.y_m + s * m.x() + c * m.y() + sy * p.x() + cy * p.y(), m.z() + p.z()};
}

Eigen::Vector3d crane_base_from_world(const MobileBaseModel& model, const BasePose& pose,
                                      const Eigen::Vector3d& w) noexcept {
  const double c = std::cos(pose.phi_rad), s = std::sin(pose.phi_rad);
  const Eigen::Vector3d& m = model.crane_mount_m;
  const double dx = w.x() - (pose.x_m + c * m.x() - s * m.y());
  const double dy = w.y() - (pose.y_m + s * m.x() + c * m.y());
  const double yaw = pose.phi_rad + model.crane_mount_yaw_rad;
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  return {cy * dx + sy * dy, -sy * dx + cy * dy, w.z() - m.z()};
}

}  // namespace craneassist::dynamics
