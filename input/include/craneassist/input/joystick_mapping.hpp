// Joystick mapping: gamepad axes and buttons -> tip-velocity command in the crane frame.
//
// Three operator axes, each fed by one gamepad axis through invert, deadband, expo and a maximum
// speed: in the cylindrical frame (what boom-tip control on forestry machines offers) lateral is
// the slew (tangential tip speed at the present radius, or a slew rate times the radius), radial
// is the horizontal reach and vertical the height; in the Cartesian frame they are z, x and y of
// the crane frame (x forward, y up, z lateral). A deadman button enables motion (the input
// monitor enforces it). docs/joystick.md is the reference.
//
// The cylindrical frame turns with the crane: map() takes the measured tip position each cycle.
// Everything here is allocation-free and exception-free.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <string>

#include "craneassist/input/gamepad.hpp"

namespace craneassist::input {

enum class MappingFrame { kCylindrical, kCartesian };
// The cylindrical lateral axis: tip speed along the arc, m/s, or slew rate, rad/s (the tip speed
// then grows with the radius, as on a machine without tip control).
enum class SlewMode { kTangential, kAngular };

// The operator axes, indices of JoystickMapping::axes.
enum class OperatorAxis { kLateral, kRadial, kVertical };
inline constexpr std::size_t kOperatorAxisCount = 3;
const char* to_string(OperatorAxis axis);

struct AxisShape {
  bool enabled = false;  // false: this operator axis is always zero
  GamepadAxis axis = GamepadAxis::kLeftX;
  double deadband =
      0.1;            // fraction of full deflection, [0, 0.9]; output rescaled to stay continuous
  double expo = 0.0;  // 0: linear .. 1: cubic (fine control near the centre)
  double max = 0.5;   // at full deflection: m/s, or rad/s for an angular slew
  bool invert = false;
};

// The drive stick's axes (sim --base), indices of JoystickMapping::drive.
enum class DriveAxis { kSpeed, kCurvature };
inline constexpr std::size_t kDriveAxisCount = 2;

struct JoystickMapping {
  MappingFrame frame = MappingFrame::kCylindrical;
  SlewMode slew = SlewMode::kTangential;
  std::array<AxisShape, kOperatorAxisCount> axes{};
  // The drive stick: forward speed and curvature as fractions of their limits (max is 1 at
  // full deflection; curvature positive: left). Disabled: no drive from this device.
  std::array<AxisShape, kDriveAxisCount> drive{};
  GamepadButton deadman = GamepadButton::kRightShoulder;
  // Below this horizontal radius the radial direction is not defined well: the last direction
  // measured outside it is kept (and an angular slew uses this radius).
  double min_radius_m = 0.3;
  // Device selection for the evdev back end: a path, or a substring of the device name; both
  // empty: the first device that looks like a gamepad.
  std::string device_path;
  std::string device_name;
};

// The SDL GameController default: left stick slew (x) and reach (y, up = out), right stick
// height (y, up = up), right shoulder (RB) the deadman; 0.12 deadband, 0.4 expo, 0.5 m/s
// tangential, 0.5 m/s radial, 0.4 m/s vertical.
JoystickMapping default_gamepad_mapping();

// One axis: raw in -1..1 (clamped; NaN stays NaN) -> invert, deadband, expo, scaled by max.
double shape_axis(const AxisShape& shape, double raw) noexcept;

// Operator-frame velocity (lateral, radial, vertical) to the crane frame.
class OperatorFrame {
 public:
  OperatorFrame(MappingFrame frame, SlewMode slew, double min_radius_m) noexcept;
  // lateral is m/s (positive: to the operator's right, i.e. clockwise seen from above) or rad/s
  // for SlewMode::kAngular; tip_m the measured tip position (crane frame). A non-finite tip
  // keeps the last direction.
  Eigen::Vector3d to_crane(const Eigen::Vector3d& operator_v,
                           const Eigen::Vector3d& tip_m) noexcept;

 private:
  MappingFrame frame_;
  SlewMode slew_;
  double min_radius_m_;
  Eigen::Vector3d radial_ = Eigen::Vector3d::UnitX();  // last good horizontal radial direction
  double radius_m_ = 0.0;
};

class JoystickMapper {
 public:
  explicit JoystickMapper(const JoystickMapping& mapping) noexcept;
  // The tip-velocity command for this gamepad state at this tip position; speed_factor (0..1)
  // scales every axis (speed steps).
  Eigen::Vector3d map(const GamepadState& pad, const Eigen::Vector3d& tip_m,
                      double speed_factor = 1.0) noexcept;
  bool deadman(const GamepadState& pad) const noexcept { return pad.button(mapping_.deadman); }
  // The drive stick (speed, curvature fractions in [-1, 1]); zero where an axis is disabled.
  Eigen::Vector2d drive(const GamepadState& pad) const noexcept;
  const JoystickMapping& mapping() const noexcept { return mapping_; }

 private:
  JoystickMapping mapping_;
  OperatorFrame frame_;
};

}  // namespace craneassist::input
