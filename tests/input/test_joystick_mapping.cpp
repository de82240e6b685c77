// The joystick mapping: axis shaping (deadband, expo, invert, max) and the cylindrical and
// Cartesian operator frames turned into the crane frame (x forward, y up, z lateral).
#include <gtest/gtest.h>

#include <cmath>

#include "allocation_counter.hpp"
#include "craneassist/input/joystick_mapping.hpp"

using namespace craneassist::input;

namespace {

AxisShape axis(double deadband, double expo, double max, bool invert = false) {
  AxisShape s;
  s.enabled = true;
  s.axis = GamepadAxis::kLeftX;
  s.deadband = deadband;
  s.expo = expo;
  s.max = max;
  s.invert = invert;
  return s;
}

}  // namespace

TEST(AxisShape, DeadbandZeroesTheCentreAndTheOutputStaysContinuous) {
  const AxisShape s = axis(0.2, 0.0, 1.0);
  EXPECT_EQ(shape_axis(s, 0.0), 0.0);
  EXPECT_EQ(shape_axis(s, 0.2), 0.0);
  EXPECT_EQ(shape_axis(s, -0.19), 0.0);
  EXPECT_NEAR(shape_axis(s, 0.2001), 0.0, 1e-3);  // no step at the edge of the deadband
  EXPECT_NEAR(shape_axis(s, 0.6), 0.5, 1e-12);    // rescaled: half way between 0.2 and 1
  EXPECT_NEAR(shape_axis(s, -1.0), -1.0, 1e-12);
}

TEST(AxisShape, ExpoMaxInvertAndClamping) {
  const AxisShape s = axis(0.0, 1.0, 0.5, true);
  EXPECT_NEAR(shape_axis(s, 0.5), -0.5 * 0.125, 1e-12);  // cubic, inverted, scaled
  EXPECT_NEAR(shape_axis(s, -1.0), 0.5, 1e-12);
  EXPECT_NEAR(shape_axis(s, -3.0), 0.5, 1e-12);  // a device beyond its range is clamped
  const AxisShape lin = axis(0.0, 0.4, 1.0);
  EXPECT_NEAR(shape_axis(lin, 0.5), 0.6 * 0.5 + 0.4 * 0.125, 1e-12);
  EXPECT_TRUE(std::isnan(shape_axis(lin, NAN)));  // NaN passes: the input monitor rejects it
  AxisShape off = lin;
  off.enabled = false;
  EXPECT_EQ(shape_axis(off, 1.0), 0.0);
}

TEST(OperatorFrame, CylindricalAxesFollowTheSlewAngle) {
  OperatorFrame f(MappingFrame::kCylindrical, SlewMode::kTangential, 0.3);
  // Tip straight ahead: radial is +x, right is +z, up is +y.
  Eigen::Vector3d v = f.to_crane({0.0, 0.4, 0.0}, {5.0, 2.0, 0.0});
  EXPECT_TRUE(v.isApprox(Eigen::Vector3d(0.4, 0.0, 0.0), 1e-12)) << v.transpose();
  v = f.to_crane({0.3, 0.0, 0.0}, {5.0, 2.0, 0.0});
  EXPECT_TRUE(v.isApprox(Eigen::Vector3d(0.0, 0.0, 0.3), 1e-12)) << v.transpose();
  v = f.to_crane({0.0, 0.0, -0.2}, {5.0, 2.0, 0.0});
  EXPECT_TRUE(v.isApprox(Eigen::Vector3d(0.0, -0.2, 0.0), 1e-12)) << v.transpose();
  // Slewed 90 degrees to the right (tip on +z): radial is +z, right is -x.
  v = f.to_crane({0.3, 0.4, 0.0}, {0.0, 1.0, 6.0});
  EXPECT_TRUE(v.isApprox(Eigen::Vector3d(-0.3, 0.0, 0.4), 1e-12)) << v.transpose();
  // At 45 degrees the tangential command is perpendicular to the radius and horizontal.
  const Eigen::Vector3d tip(3.0, 0.5, 3.0);
  v = f.to_crane({0.5, 0.0, 0.0}, tip);
  EXPECT_NEAR(v.dot(Eigen::Vector3d(tip.x(), 0.0, tip.z())), 0.0, 1e-12);
  EXPECT_NEAR(v.norm(), 0.5, 1e-12);
}

TEST(OperatorFrame, AngularSlewScalesWithRadiusAndSmallRadiusKeepsDirection) {
  OperatorFrame f(MappingFrame::kCylindrical, SlewMode::kAngular, 0.3);
  Eigen::Vector3d v = f.to_crane({0.1, 0.0, 0.0}, {0.0, 0.0, -4.0});  // 0.1 rad/s at 4 m
  EXPECT_TRUE(v.isApprox(Eigen::Vector3d(0.4, 0.0, 0.0), 1e-12)) << v.transpose();
  // Over the slew axis: the last radial direction (-z) is kept, the radius floored.
  v = f.to_crane({0.1, 0.2, 0.0}, {0.05, 3.0, 0.0});
  EXPECT_TRUE(v.isApprox(Eigen::Vector3d(0.1 * 0.3, 0.0, -0.2), 1e-12)) << v.transpose();
  // No valid measurement: the same.
  v = f.to_crane({0.0, 0.2, 0.0}, Eigen::Vector3d::Constant(NAN));
  EXPECT_TRUE(v.isApprox(Eigen::Vector3d(0.0, 0.0, -0.2), 1e-12)) << v.transpose();
}

TEST(OperatorFrame, CartesianIsTheCraneFrame) {
  OperatorFrame f(MappingFrame::kCartesian, SlewMode::kTangential, 0.3);
  const Eigen::Vector3d v = f.to_crane({0.1, 0.2, 0.3}, {0.0, 0.0, 7.0});
  EXPECT_TRUE(v.isApprox(Eigen::Vector3d(0.2, 0.3, 0.1), 1e-12)) << v.transpose();
}

TEST(JoystickMapper, DefaultGamepadLayout) {
  JoystickMapper m(default_gamepad_mapping());
  GamepadState pad;
  pad.set_axis(GamepadAxis::kLeftY, -1.0);   // left stick pushed away: reach out
  pad.set_axis(GamepadAxis::kRightY, -1.0);  // right stick pushed away: up
  pad.set_axis(GamepadAxis::kLeftX, 0.05);   // inside the deadband
  Eigen::Vector3d v = m.map(pad, {5.0, 2.0, 0.0});
  EXPECT_TRUE(v.isApprox(Eigen::Vector3d(0.5, 0.4, 0.0), 1e-12)) << v.transpose();
  EXPECT_FALSE(m.deadman(pad));
  pad.set_button(GamepadButton::kRightShoulder, true);
  EXPECT_TRUE(m.deadman(pad));
  pad = {};
  pad.set_axis(GamepadAxis::kLeftX, -1.0);  // left: slew left, -z straight ahead
  v = m.map(pad, {5.0, 2.0, 0.0}, 0.5);     // half speed
  EXPECT_TRUE(v.isApprox(Eigen::Vector3d(0.0, 0.0, -0.25), 1e-12)) << v.transpose();
}

TEST(JoystickMapper, MapAllocatesNothing) {
  JoystickMapper m(default_gamepad_mapping());
  GamepadState pad;
  pad.set_axis(GamepadAxis::kLeftX, 0.7);
  const long before = craneassist::test::heap_allocations();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i < 1000; ++i) sum += m.map(pad, {4.0, 1.0, 0.001 * i});
  EXPECT_EQ(craneassist::test::heap_allocations(), before);
  EXPECT_GT(sum.norm(), 0.0);
}

TEST(Gamepad, NamesRoundTrip) {
  for (std::size_t i = 0; i < kGamepadAxisCount; ++i) {
    GamepadAxis a;
    ASSERT_TRUE(parse_gamepad_axis(to_string(static_cast<GamepadAxis>(i)), a));
    EXPECT_EQ(static_cast<std::size_t>(a), i);
  }
  for (std::size_t i = 0; i < kGamepadButtonCount; ++i) {
    GamepadButton b;
    ASSERT_TRUE(parse_gamepad_button(to_string(static_cast<GamepadButton>(i)), b));
    EXPECT_EQ(static_cast<std::size_t>(b), i);
  }
  GamepadAxis a;
  EXPECT_FALSE(parse_gamepad_axis("left_z", a));
}
