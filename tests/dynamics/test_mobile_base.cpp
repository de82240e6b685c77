// The double-Ackermann base (dynamics/mobile_base.hpp, docs/mobile.md): the wheel inverse
// kinematics against the instantaneous centre of rotation found numerically, the steering limit,
// the hub-motor flows, and its config (config/machines/mobile_base.yaml) and its errors.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

#include "craneassist/config/base_config.hpp"
#include "craneassist/config/config_error.hpp"
#include "craneassist/dynamics/mobile_base.hpp"
#include "thrown_error.hpp"

namespace {

using craneassist::config::ConfigError;
using namespace craneassist::dynamics;

const std::string kBasePath =
    std::string(CRANEASSIST_SOURCE_DIR) + "/config/machines/mobile_base.yaml";

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

MobileBaseModel shipped() {
  return craneassist::config::load_base_config(kBasePath).model;
}

// The chassis point at p (in {b}) moves with (v - omega p_y, omega p_x).
Eigen::Vector2d chassis_velocity(double v, double omega, const Eigen::Vector2d& p) {
  return {v - omega * p.y(), omega * p.x()};
}

// The instantaneous centre of rotation found numerically, without the formula the model uses:
// the point of the plane whose velocity is zero, by Newton's method on the chassis velocity
// field differenced at two points.
Eigen::Vector2d icr_numerically(double v, double omega) {
  Eigen::Vector2d p(0.3, -0.2);
  for (int it = 0; it < 50; ++it) {
    const double h = 1e-6;
    const Eigen::Vector2d f = chassis_velocity(v, omega, p);
    Eigen::Matrix2d jac;
    jac.col(0) = (chassis_velocity(v, omega, p + Eigen::Vector2d(h, 0)) - f) / h;
    jac.col(1) = (chassis_velocity(v, omega, p + Eigen::Vector2d(0, h)) - f) / h;
    p -= jac.fullPivLu().solve(f);
  }
  return p;
}

}  // namespace

TEST(MobileBase, WheelsRollAboutTheInstantaneousCentreOfRotation) {
  const MobileBaseModel model = shipped();
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> speed(-0.5, 0.5);
  std::uniform_real_distribution<double> curvature(-0.99 * max_curvature_1_m(model),
                                                   0.99 * max_curvature_1_m(model));
  for (int trial = 0; trial < 200; ++trial) {
    const double v = speed(rng);
    const double kappa = curvature(rng);
    if (std::abs(v) < 1e-3 || std::abs(kappa) < 1e-3) continue;
    const double omega = kappa * v;
    WheelState w;
    wheel_inverse_kinematics(model, omega, v, w);
    EXPECT_FALSE(w.steer_limited);
    const Eigen::Vector2d icr = icr_numerically(v, omega);
    for (int i = 0; i < kBaseWheels; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const Eigen::Vector2d c = wheel_centre(model, i, w.steer_rad[k]);
      const Eigen::Vector2d heading(std::cos(w.steer_rad[k]), std::sin(w.steer_rad[k]));
      const Eigen::Vector2d to_icr = icr - c;
      // The wheel rolls perpendicular to the line to the ICR: its heading is normal to it, and
      // so is its axle through the steering pivot.
      EXPECT_NEAR(heading.dot(to_icr.normalized()), 0.0, 1e-9) << wheel_name(i);
      const Eigen::Vector2d pivot_to_icr = icr - steering_pivot(model, i);
      EXPECT_NEAR(heading.dot(pivot_to_icr.normalized()), 0.0, 1e-9) << wheel_name(i);
      // Its speed is the yaw rate times its distance to the ICR, the same ratio for every wheel.
      EXPECT_NEAR(std::abs(w.speed_m_s[k]), std::abs(omega) * to_icr.norm(), 1e-9) << wheel_name(i);
      // It moves the way the chassis point under it does (no side slip, no skid).
      const Eigen::Vector2d vc = chassis_velocity(v, omega, c);
      EXPECT_NEAR((vc - w.speed_m_s[k] * heading).norm(), 0.0, 1e-9) << wheel_name(i);
      // Forward with the chassis when the ICR is outside the track.
      EXPECT_GT(w.speed_m_s[k] * v, 0.0) << wheel_name(i);
      // Motor speed and flow from the wheel speed (eq. 5, Q = |n| V_m).
      EXPECT_NEAR(w.motor_speed_rad_s[k], w.speed_m_s[k] / model.wheel_radius_m * model.gear_ratio,
                  1e-9);
      EXPECT_NEAR(
          w.flow_m3_s[k],
          std::abs(w.motor_speed_rad_s[k]) / (2 * std::numbers::pi) * model.motor_displacement_m3,
          1e-15);
    }
    // Mirrored (negative 4WS): the rear wheels steer opposite to the front ones.
    EXPECT_NEAR(w.steer_rad[0], -w.steer_rad[2], 1e-12);
    EXPECT_NEAR(w.steer_rad[1], -w.steer_rad[3], 1e-12);
  }
}

TEST(MobileBase, StraightAheadEveryWheelAtTheSameSpeed) {
  const MobileBaseModel model = shipped();
  WheelState w;
  wheel_inverse_kinematics(model, 0.0, 0.25, w);
  for (std::size_t k = 0; k < kBaseWheels; ++k) {
    EXPECT_EQ(w.steer_rad[k], 0.0);
    EXPECT_DOUBLE_EQ(w.speed_m_s[k], 0.25);
  }
  // 63 L/min through four 100 cm^3 motors behind a 17.7 gear on 0.35 m wheels: the fastest
  // straight drive is 63e-3/60 / 4 / 100e-6 / 17.7 * 2 pi 0.35 = 0.326 m/s.
  const double v_max = model.pump_max_flow_m3_s / flow_per_speed_m2(model, 0.0);
  EXPECT_NEAR(v_max, 63e-3 / 60 / 4 / 100e-6 / 17.7 * 2 * std::numbers::pi * 0.35, 1e-12);
}

TEST(MobileBase, SteeringLimitGivesThePapersTurningRadius) {
  const MobileBaseModel model = shipped();
  // The paper: +-45 deg at the wheels, the outer wheels turn on 3.75 m at the tightest.
  EXPECT_NEAR(min_outer_turning_radius_m(model), 3.75, 0.01);
  const double kappa = max_curvature_1_m(model);
  WheelState w;
  wheel_inverse_kinematics(model, kappa * 0.2, 0.2, w);
  double largest = 0.0;
  for (const double psi : w.steer_rad) largest = std::max(largest, std::abs(psi));
  EXPECT_NEAR(largest, std::numbers::pi / 4, 1e-12);
  EXPECT_FALSE(w.steer_limited);
  wheel_inverse_kinematics(model, kappa * 1.05 * 0.2, 0.2, w);
  EXPECT_TRUE(w.steer_limited);
  EXPECT_DOUBLE_EQ(limit_yaw_rate(model, 0.2, 1.0), kappa * 0.2);
  EXPECT_DOUBLE_EQ(limit_yaw_rate(model, -0.2, -1.0), -kappa * 0.2);
  EXPECT_DOUBLE_EQ(limit_yaw_rate(model, 0.0, 0.3), 0.0);
  // Turning on the spot is out of reach of this steering.
  wheel_inverse_kinematics(model, 0.1, 0.0, w);
  EXPECT_TRUE(w.steer_limited);
}

TEST(MobileBase, FlowSumIsHomogeneousAndConvex) {
  const MobileBaseModel model = shipped();
  const double kmax = max_curvature_1_m(model);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto flow = [&](double v, double omega) {
    WheelState w;
    wheel_inverse_kinematics(model, omega, v, w);
    return w.flow_sum_m3_s;
  };
  for (int trial = 0; trial < 200; ++trial) {
    const double v1 = 0.05 + 0.4 * std::abs(u(rng)), v2 = 0.05 + 0.4 * std::abs(u(rng));
    const double o1 = kmax * v1 * u(rng), o2 = kmax * v2 * u(rng);
    EXPECT_NEAR(flow(2 * v1, 2 * o1), 2 * flow(v1, o1), 1e-15);
    EXPECT_NEAR(flow(v1, o1), v1 * flow_per_speed_m2(model, o1 / v1), 1e-15);
    // Convex in (v, omega): what keeps the lagged motion within the bound (docs/mobile.md).
    const double a = 0.5 * (1.0 + u(rng));
    EXPECT_LE(flow(a * v1 + (1 - a) * v2, a * o1 + (1 - a) * o2),
              a * flow(v1, o1) + (1 - a) * flow(v2, o2) + 1e-15);
  }
  // A turn takes more flow than straight ahead at the same speed.
  EXPECT_GT(flow_per_speed_m2(model, 0.8 * kmax), flow_per_speed_m2(model, 0.0));
}

TEST(MobileBase, PoseIntegrationFollowsTheArc) {
  BasePose p;
  const double v = 0.3, omega = 0.1;
  for (int k = 0; k < 1000; ++k) p = integrate_pose(p, v, omega, 0.01);
  // 10 s on a circle of radius 3 m about (0, 3).
  EXPECT_NEAR(p.phi_rad, 1.0, 1e-12);
  EXPECT_NEAR(p.x_m, 3.0 * std::sin(1.0), 1e-12);
  EXPECT_NEAR(p.y_m, 3.0 - 3.0 * std::cos(1.0), 1e-12);
}

TEST(MobileBase, CraneFrameRoundTrip) {
  MobileBaseModel model = shipped();
  model.crane_mount_m = Eigen::Vector3d(0.4, -0.2, 0.8);
  model.crane_mount_yaw_rad = 0.3;
  const BasePose pose{2.0, -1.0, 0.7};
  const Eigen::Vector3d p(4.0, 1.0, 2.0);
  const Eigen::Vector3d w = world_from_crane_base(model, pose, p);
  EXPECT_NEAR((crane_base_from_world(model, pose, w) - p).norm(), 0.0, 1e-12);
  // The mount's origin sits at the chassis point (0.4, -0.2) turned by phi.
  const Eigen::Vector3d o = world_from_crane_base(model, pose, Eigen::Vector3d::Zero());
  EXPECT_NEAR(o.x(), 2.0 + 0.4 * std::cos(0.7) + 0.2 * std::sin(0.7), 1e-12);
  EXPECT_NEAR(o.y(), -1.0 + 0.4 * std::sin(0.7) - 0.2 * std::cos(0.7), 1e-12);
  EXPECT_NEAR(o.z(), 0.8, 1e-12);
}

TEST(MobileBase, LagIsFirstOrder) {
  MobileBaseModel model = shipped();
  model.time_constant_s = 0.5;
  BaseVelocity v;
  for (int k = 0; k < 50; ++k) v = lag_velocity(model, v, {1.0, 0.2}, 0.01);
  EXPECT_NEAR(v.v_m_s, 1.0 - std::exp(-1.0), 1e-12);
  EXPECT_NEAR(v.omega_rad_s, 0.2 * (1.0 - std::exp(-1.0)), 1e-12);
}

TEST(BaseConfig, ShippedAndEmbeddedAgree) {
  const auto file = craneassist::config::load_base_config(kBasePath);
  const auto embedded = craneassist::config::default_base_config();
  EXPECT_EQ(file.model.name, embedded.model.name);
  EXPECT_DOUBLE_EQ(file.model.pump_max_flow_m3_s, 63e-3 / 60.0);
  EXPECT_DOUBLE_EQ(file.model.motor_displacement_m3, 100e-6);
  EXPECT_DOUBLE_EQ(file.model.gear_ratio, 17.7);
  EXPECT_DOUBLE_EQ(file.model.steer_max_rad, std::numbers::pi / 4);
  EXPECT_EQ(file.model.motor_speed_max_rad_s, 0.0);
  EXPECT_DOUBLE_EQ(embedded.following.tool_offset_m, file.following.tool_offset_m);
}

TEST(BaseConfig, ErrorsNameFileLineAndField) {
  const std::string text = read_file(kBasePath);
  struct Case {
    const char* from;
    const char* to;
    const char* field;
    const char* reason;
  };
  const Case cases[] = {
      {"steer_max: 45 deg, paper", "steer_max: 95 deg, paper", "chassis.steer_max",
       "between 1 deg and 80 deg"},
      {"gear_ratio: 17.7, paper", "gear_ratio: 17.7", "drive.gear_ratio", "missing source"},
      {"pump_max_flow: 63 L/min, paper", "pump_max_flow: 63 bar, paper", "drive.pump_max_flow",
       "not a volume flow unit"},
      {"motor_displacement: 100 cm^3", "motor_displacment: 100 cm^3", "drive.motor_displacment",
       "unknown field"},
      {"k2: 0.9, assumed", "k2: 1.5, assumed", "path_following.k2", "in (0, 1]"},
      {"  wheel_radius: 0.35 m, assumed\n", "", "chassis.wheel_radius", "missing"},
      {"arm_shares_pump: false", "arm_shares_pump: maybe", "drive.arm_shares_pump",
       "expected true or false"},
  };
  for (const Case& c : cases) {
    std::string edited = text;
    const auto pos = edited.find(c.from);
    ASSERT_NE(pos, std::string::npos) << c.from;
    edited.replace(pos, std::string(c.from).size(), c.to);
    const ConfigError e = craneassist::test::thrown_error<ConfigError>(
        [&] { craneassist::config::parse_base_config(edited, "edited.yaml"); },
        std::string("accepted ") + c.to);
    EXPECT_EQ(e.file(), "edited.yaml");
    EXPECT_EQ(e.field(), c.field) << e.what();
    EXPECT_NE(e.reason().find(c.reason), std::string::npos) << e.what();
    if (std::string(c.to).empty()) {
      EXPECT_GT(e.line(), 0);
    } else {
      const int line = 1 + static_cast<int>(std::count(
                               edited.begin(), edited.begin() + static_cast<long>(pos), '\n'));
      EXPECT_EQ(e.line(), line) << e.what();
    }
  }
}
