// The wheeled base of the mobile crane: a double-Ackermann (four-wheel-steered) platform with a
// hydraulic hub motor in every wheel ("Flow-limited path-following control of a double Ackermann
// steered hydraulic mobile manipulator", section II; docs/mobile.md).
//
// Frames: the world frame {w} (x, y in the ground plane, z up) and the chassis frame {b} at the
// chassis centre, x forward, y left, z up. The base pose is (x, y, phi) of {b} in {w}.
//
// Kinematics, in the paper's negative 4WS mode (front and rear wheels steered by mirrored
// angles), as the bicycle model of eq. 1: the chassis moves with forward speed v and yaw rate
// omega, and its instantaneous centre of rotation (ICR) lies on the chassis y axis at
// y = v / omega. Wheel inverse kinematics (eqs. 2-5): the velocity of each steering pivot
// l_i = (l_ix, l_iy) is v_si = (v - omega l_iy, omega l_ix), its steering angle
// psi_i = atan(v_siy / v_six); the wheel centre sits d outboard of the pivot along the wheel's
// axle, so it lies on the same line to the ICR and moves with v_mi = v_si + omega x (d n_i)
// (n_i the outboard axle direction); its hub motor turns at n_i = v_mi k_gear / r_wheel (signed
// along the wheel's heading) and draws Q_i = |n_i| V_m / (2 pi).
//
// Wheel order: front left, front right, rear left, rear right.
//
// Model / data split as for the crane: MobileBaseModel is loaded once (config/), WheelState is
// the per-evaluation output. Every function here allocates nothing and throws nothing.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

namespace craneassist::dynamics {

inline constexpr int kBaseWheels = 4;
// "front left", "front right", "rear left", "rear right".
const char* wheel_name(int wheel);

struct MobileBaseModel {
  std::string name;
  // Steering pivots at (+-half_length, +-half_width) from the chassis centre (l_ix, l_iy).
  double half_length_m = 1.5;
  double half_width_m = 0.886;
  double wheel_offset_m = 0.15;  // d: wheel centre outboard of its steering pivot
  double wheel_radius_m = 0.35;
  double steer_max_rad = 0.7853981633974483;  // |psi_i| limit of every wheel
  double motor_displacement_m3 = 100e-6;      // V_m, per revolution of the hub motor
  double gear_ratio = 17.7;                   // k_gear: motor revolutions per wheel revolution
  double pump_max_flow_m3_s = 63e-3 / 60.0;   // Q_max of the drive pump
  double motor_speed_max_rad_s = 0.0;         // n_max per hub motor; 0: no such limit
  // First-order lag of the velocity inputs (forward speed and yaw rate), as in the paper's
  // simulation. One time constant for both keeps the lagged motion a convex combination of the
  // commands, so a command sequence within the sum-flow bound stays within it after the lag.
  double time_constant_s = 0.3;
  // Where the crane stands on the chassis: its DH base-frame origin in {b}, and the yaw of its
  // slew zero (the DH x0 axis) from the chassis x axis.
  Eigen::Vector3d crane_mount_m = Eigen::Vector3d::Zero();
  double crane_mount_yaw_rad = 0.0;
};

struct BasePose {
  double x_m = 0.0;
  double y_m = 0.0;
  double phi_rad = 0.0;
};

// The wheels for one chassis motion (v, omega).
struct WheelState {
  std::array<double, kBaseWheels> steer_rad{};          // psi_i, in (-pi/2, pi/2)
  std::array<double, kBaseWheels> speed_m_s{};          // wheel centre speed along its heading
  std::array<double, kBaseWheels> motor_speed_rad_s{};  // hub motor, signed like speed_m_s
  std::array<double, kBaseWheels> flow_m3_s{};          // |n_i| V_m / (2 pi)
  double flow_sum_m3_s = 0.0;
  bool steer_limited = false;  // some |psi_i| exceeds steer_max_rad (the motion is not feasible)
};

// The steering pivot l_i and the outboard unit axle direction at steering angle psi, in {b}.
Eigen::Vector2d steering_pivot(const MobileBaseModel& model, int wheel) noexcept;
Eigen::Vector2d wheel_centre(const MobileBaseModel& model, int wheel, double steer_rad) noexcept;

// Eqs. 2-5 for the chassis motion (omega, v): steering angles, wheel speeds, motor speeds and
// flows. A turn on the spot (v = 0, omega != 0) gives steering angles of about 60 deg on a
// square-ish chassis and is reported steer_limited.
void wheel_inverse_kinematics(const MobileBaseModel& model, double omega_rad_s, double v_m_s,
                              WheelState& out) noexcept;

// The tightest turn the steering limit allows: the inner wheels at steer_max. Curvature of the
// chassis centre's path, 1/m (the ICR at l_x / tan(steer_max) + l_y from the centre).
double max_curvature_1_m(const MobileBaseModel& model) noexcept;
// The radius on which the outer wheel centres turn at the tightest turn (the paper's r_min).
double min_outer_turning_radius_m(const MobileBaseModel& model) noexcept;

// omega clamped to the steering limit at forward speed v: |omega| <= max_curvature |v|.
double limit_yaw_rate(const MobileBaseModel& model, double v_m_s, double omega_rad_s) noexcept;

// The sum of the hub-motor flows per unit forward speed at curvature kappa = omega / v (for
// v > 0; the sum is homogeneous of degree one in (v, omega)), m^3/s per m/s.
double flow_per_speed_m2(const MobileBaseModel& model, double curvature_1_m) noexcept;

// The highest of the motor speeds per unit forward speed at curvature kappa, rad/s per m/s.
double motor_speed_per_speed_1_m(const MobileBaseModel& model, double curvature_1_m) noexcept;

// Eq. 1 integrated over dt with (v, omega) constant: an exact arc.
BasePose integrate_pose(const BasePose& pose, double v_m_s, double omega_rad_s,
                        double dt_s) noexcept;

// The base's actuated velocities with the first-order lag of the paper's simulation.
struct BaseVelocity {
  double v_m_s = 0.0;
  double omega_rad_s = 0.0;
};
// One step of the lag (exact discretisation of tau x' = u - x) towards the command.
BaseVelocity lag_velocity(const MobileBaseModel& model, const BaseVelocity& current,
                          const BaseVelocity& command, double dt_s) noexcept;

// A point given in the crane's DH base frame, in world coordinates, for the base at `pose`
// (the ground plane is the crane's z0 = 0 plane shifted by crane_mount_m.z()).
Eigen::Vector3d world_from_crane_base(const MobileBaseModel& model, const BasePose& pose,
                                      const Eigen::Vector3d& p_crane_base_m) noexcept;
// And back: a world point in the crane's DH base frame.
Eigen::Vector3d crane_base_from_world(const MobileBaseModel& model, const BasePose& pose,
                                      const Eigen::Vector3d& p_world_m) noexcept;

}  // namespace craneassist::dynamics
