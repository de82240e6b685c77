// The operator's drive of the wheeled base (scaling/base_drive.hpp): at every stick position
// the summed hub-motor flow of the command is within the budget, full stick reaches it, the
// curvature stops at the steering limit, and a broken input stands still.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "craneassist/config/base_config.hpp"
#include "craneassist/scaling/base_drive.hpp"

namespace {

using namespace craneassist;

}  // namespace

TEST(BaseDrive, FlowNeverAboveTheBudgetAndFullStickReachesIt) {
  const dynamics::MobileBaseModel m = config::default_base_config().model;
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.3, 1.3);  // beyond the stick's travel too
  scaling::BaseDriveOutput out;
  dynamics::WheelState w;
  for (const double budget : {m.pump_max_flow_m3_s, 0.4 * m.pump_max_flow_m3_s}) {
    for (int k = 0; k < 2000; ++k) {
      const double speed = u(rng), curvature = u(rng);
      scaling::flow_bounded_drive(m, speed, curvature, budget, out);
      dynamics::wheel_inverse_kinematics(m, out.omega_rad_s, out.v_m_s, w);
      ASSERT_LE(w.flow_sum_m3_s, budget * (1 + 1e-9)) << speed << " " << curvature;
      ASSERT_FALSE(w.steer_limited) << speed << " " << curvature;
      ASSERT_LE(std::abs(out.curvature_1_m), dynamics::max_curvature_1_m(m) * (1 + 1e-12));
      if (std::abs(speed) >= 1.0) {
        EXPECT_NEAR(w.flow_sum_m3_s, budget, 1e-9 * budget);  // full stick: the whole budget
      }
    }
  }
  // Straight ahead at full stick: 63 L/min over four 100 cm^3 motors through 17.7 on 0.35 m
  // wheels (docs/mobile.md: 0.326 m/s).
  scaling::flow_bounded_drive(m, 1.0, 0.0, m.pump_max_flow_m3_s, out);
  const double v_straight = m.pump_max_flow_m3_s / 4.0 / m.motor_displacement_m3 / m.gear_ratio *
                            2.0 * 3.14159265358979323846 * m.wheel_radius_m;
  EXPECT_NEAR(out.v_m_s, v_straight, 1e-12);
  EXPECT_EQ(out.omega_rad_s, 0.0);
  // Half stick back, full left: half the bound at the tightest turn, backwards.
  scaling::flow_bounded_drive(m, -0.5, 1.0, m.pump_max_flow_m3_s, out);
  EXPECT_DOUBLE_EQ(out.curvature_1_m, dynamics::max_curvature_1_m(m));
  EXPECT_NEAR(out.v_m_s, -0.5 * out.v_max_m_s, 1e-15);
  EXPECT_LT(out.v_max_m_s, v_straight);  // a turn costs flow: the outer wheels run faster
}

TEST(BaseDrive, MotorSpeedLimitAndBrokenInput) {
  dynamics::MobileBaseModel m = config::default_base_config().model;
  scaling::BaseDriveOutput out;
  m.motor_speed_max_rad_s = 10.0;  // the flow bound straight ahead: 16.5 rad/s
  scaling::flow_bounded_drive(m, 1.0, 0.0, m.pump_max_flow_m3_s, out);
  EXPECT_EQ(out.limit, scaling::BaseLimit::kMotorSpeed);
  dynamics::WheelState w;
  dynamics::wheel_inverse_kinematics(m, out.omega_rad_s, out.v_m_s, w);
  for (const double n : w.motor_speed_rad_s) EXPECT_LE(std::abs(n), 10.0 * (1 + 1e-9));
  for (const double bad : {std::nan(""), HUGE_VAL}) {
    scaling::flow_bounded_drive(m, bad, 0.0, m.pump_max_flow_m3_s, out);
    EXPECT_EQ(out.v_m_s, 0.0);
    scaling::flow_bounded_drive(m, 1.0, bad, m.pump_max_flow_m3_s, out);
    EXPECT_EQ(out.v_m_s, 0.0);
    EXPECT_EQ(out.omega_rad_s, 0.0);
  }
  scaling::flow_bounded_drive(m, 1.0, 0.0, -1.0, out);  // no budget: stand still
  EXPECT_EQ(out.v_m_s, 0.0);
}
