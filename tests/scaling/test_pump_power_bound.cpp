// The path scaler's pump-power bound for the two pump modes: (max load + dp_LS) Q for a
// load-sensing pump, p_s Q (a speed limit) and max load + dp_c <= p_s for a constant-pressure
// pump.
#include <gtest/gtest.h>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/scaling/path_constraints.hpp"

using namespace craneassist;
using dynamics::JointVector;

namespace {

// The K70M lifting alone along the path: 0.1 m/s of lift cylinder extension per unit path speed
// (dc/dq = 1, so joint rates are cylinder velocities), with a static load pressure of
// `static_pa` and 3.5 MPa more per unit path acceleration.
struct Fixture {
  explicit Fixture(double static_pa) {
    path.f1 = JointVector::Zero(4);
    path.f1[1] = 0.1;
    path.f2 = JointVector::Zero(4);
    path.dc_dq = JointVector::Ones(4);
    path.d2c_dq2 = JointVector::Zero(4);
    const double area = model.cylinders[1].area_a_m2;
    terms.m = JointVector::Zero(4);
    terms.b = JointVector::Zero(4);
    terms.m[1] = 3.5e6 * area;
    terms.b[1] = static_pa * area;
    limits.path_acceleration_max = 100.0;
    limits.path_deceleration_max = 100.0;
  }
  scaling::AccelerationBounds bounds(dynamics::PumpMode mode, double sdot) {
    model.pump.mode = mode;
    scaling::AccelerationBounds b;
    scaling::path_acceleration_bounds(model, path, terms, sdot, limits, b);
    return b;
  }
  double flow_per_speed() const { return 0.1 * model.cylinders[1].area_a_m2; }

  dynamics::CraneModel model = config::default_crane_config().model;  // 20 MPa, dp 3 MPa, 35 kW
  scaling::PathGeometry path;
  dynamics::PathTerms terms;
  scaling::AccelerationLimits limits;
};

constexpr auto kLs = dynamics::PumpMode::kLoadSensing;
constexpr auto kCp = dynamics::PumpMode::kConstantPressure;

}  // namespace

TEST(PumpPowerBound, ConstantPressurePowerIsASpeedLimitAtTheSetpoint) {
  Fixture f(10e6);
  ASSERT_DOUBLE_EQ(f.model.pump.supply_pressure_pa, 20e6);
  const double cp_speed = 35e3 / (20e6 * f.flow_per_speed());
  const auto cp = f.bounds(kCp, 0.5 * cp_speed);
  EXPECT_NEAR(cp.sdot_power, cp_speed, 1e-12 * cp_speed);
  // The LS pump at 10 + 3 MPa allows more speed: the LS bound would be wrong for a CP pump.
  const auto ls = f.bounds(kLs, 0.5 * cp_speed);
  EXPECT_NEAR(ls.sdot_power, 35e3 / (13e6 * f.flow_per_speed()), 1e-9);
  EXPECT_GT(ls.sdot_power, 1.5 * cp.sdot_power);
  // The power reserve shrinks it like the LS bound.
  f.limits.power_reserve = 0.2;
  EXPECT_NEAR(f.bounds(kCp, 0.0).sdot_power, 0.8 * cp_speed, 1e-12 * cp_speed);
}

TEST(PumpPowerBound, ConstantPressureKeepsTheLoadPressureBelowTheSetpointMinusTheMargin) {
  Fixture f(10e6);
  const auto cp = f.bounds(kCp, 1.0);
  EXPECT_DOUBLE_EQ(cp.pressure_limit_pa, 17e6);
  // 10 MPa + 3.5 MPa per unit sddot reaches 17 MPa at sddot = 2 (the cylinder's own 0.4 m/s^2
  // would allow 4).
  EXPECT_NEAR(cp.sddot_max, 2.0, 1e-9);
  EXPECT_EQ(cp.limit_max, scaling::ActiveLimit::kPressure);  // the supply pressure, not power
  // Unlike the LS bound the CP one does not tighten with speed (p_s Q has no sddot term).
  EXPECT_NEAR(f.bounds(kCp, 5.0).sddot_max, 2.0, 1e-9);
  EXPECT_LT(f.bounds(kLs, 5.0).sddot_max, f.bounds(kLs, 1.0).sddot_max);
  // A static load above p_s - dp_c starves the section: no speed is admissible, where the LS pump
  // (relief 21.5 MPa) still moves it.
  Fixture heavy(18e6);
  EXPECT_EQ(heavy.bounds(kCp, 0.1).sdot_power, 0.0);
  EXPECT_GT(heavy.bounds(kLs, 0.1).sdot_power, 0.0);
}

TEST(PumpPowerBound, PumpPowerFollowsTheMode) {
  Fixture f(10e6);
  const double sdot = 0.5, sddot = 1.0;
  const double flow = f.flow_per_speed() * sdot;
  f.model.pump.mode = kCp;
  EXPECT_NEAR(scaling::pump_power(f.model, f.path, f.terms, sdot, sddot), 20e6 * flow, 1e-9);
  f.model.pump.mode = kLs;
  const double ls = (10e6 + 3.5e6 * sddot + 3e6) * flow;
  EXPECT_NEAR(scaling::pump_power(f.model, f.path, f.terms, sdot, sddot), ls, 1e-6);
  EXPECT_NEAR(scaling::load_sensing_power(f.model, f.path, f.terms, sdot, sddot), ls, 1e-6);
}

// Slowing down is never held back by the pump: where decelerating raises the load pressure
// (negative m: e.g. a heavy load being lowered fast) past what P_max / Q or relief leave, the
// bound still allows the path's full deceleration. Before, it asked for sddot > 0 there and a
// released stick could not stop the reference.
TEST(PumpPowerBound, NeverBoundsTheDeceleration) {
  for (const auto mode : {kLs, kCp}) {
    for (const double static_pa : {10e6, 16e6, 21e6}) {
      Fixture f(static_pa);
      f.terms.m[1] = -3.5e6 * f.model.cylinders[1].area_a_m2;  // slowing raises the pressure
      f.limits.path_deceleration_max = 1.0;
      for (const double sdot : {0.1, 1.0, 5.0}) {
        const auto b = f.bounds(mode, sdot);
        SCOPED_TRACE(testing::Message() << "mode " << static_cast<int>(mode) << " static "
                                        << static_pa << " sdot " << sdot);
        EXPECT_DOUBLE_EQ(b.sddot_min, -1.0);
        EXPECT_EQ(b.limit_min, scaling::ActiveLimit::kNone);
        // It still caps the acceleration side where it binds.
        EXPECT_LE(b.sddot_max, f.limits.path_acceleration_max);
      }
    }
  }
  // The actuator-power-sum baseline likewise.
  Fixture f(16e6);
  f.terms.m[1] = -3.5e6 * f.model.cylinders[1].area_a_m2;
  f.limits.path_deceleration_max = 1.0;
  f.limits.power_bound = scaling::PowerBound::kActuatorPowerSum;
  EXPECT_DOUBLE_EQ(f.bounds(kLs, 5.0).sddot_min, -1.0);
}
