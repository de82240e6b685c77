#include "craneassist/input/joystick_mapping.hpp"

#include <algorithm>
#include <cmath>

namespace craneassist::input {

const char* to_string(OperatorAxis axis) {
  switch (axis) {
    case OperatorAxis::kLateral:
      return "lateral";
    case OperatorAxis::kRadial:
      return "radial";
    case OperatorAxis::kVertical:
      return "vertical";
  }
  return "unknown";
}

JoystickMapping default_gamepad_mapping() {
  JoystickMapping m;
  auto shape = [](GamepadAxis axis, double max, bool invert) {
    AxisShape s;
    s.enabled = true;
    s.axis = axis;
    s.deadband = 0.12;
    s.expo = 0.4;
    s.max = max;
    s.invert = invert;
    return s;
  };
  m.axes[static_cast<std::size_t>(OperatorAxis::kLateral)] = shape(GamepadAxis::kLeftX, 0.5, false);
  // Sticks report y down: invert so pushing the stick away moves the tip out and up.
  m.axes[static_cast<std::size_t>(OperatorAxis::kRadial)] = shape(GamepadAxis::kLeftY, 0.5, true);
  m.axes[static_cast<std::size_t>(OperatorAxis::kVertical)] =
      shape(GamepadAxis::kRightY, 0.4, true);
  return m;
}

double shape_axis(const AxisShape& shape, double raw) noexcept {
  if (!shape.enabled) return 0.0;
  if (std::isnan(raw)) return raw;
  double x = std::clamp(raw, -1.0, 1.0);
  if (shape.invert) x = -x;
  const double mag = std::abs(x);
  if (mag <= shape.deadband) return 0.0;
  const double u = (mag - shape.deadband) / (1.0 - shape.deadband);
  const double curved = (1.0 - shape.expo) * u + shape.expo * u * u * u;
  return std::copysign(curved * shape.max, x);
}

OperatorFrame::OperatorFrame(MappingFrame frame, SlewMode slew, double min_radius_m) noexcept
    : frame_(frame), slew_(slew), min_radius_m_(min_radius_m) {}

Eigen::Vector3d OperatorFrame::to_crane(const Eigen::Vector3d& v,
                                        const Eigen::Vector3d& tip_m) noexcept {
  const double lateral = v[0], radial = v[1], vertical = v[2];
  if (frame_ == MappingFrame::kCartesian) return {radial, vertical, lateral};
  if (tip_m.allFinite()) {
    const double r = std::hypot(tip_m.x(), tip_m.z());
    if (r >= min_radius_m_) {
      radial_ = Eigen::Vector3d(tip_m.x() / r, 0.0, tip_m.z() / r);
      radius_m_ = r;
    } else {
      radius_m_ = min_radius_m_;
    }
  }
  // To the operator's right (x forward, y up: right is +z at a tip straight ahead).
  const Eigen::Vector3d tangential(-radial_.z(), 0.0, radial_.x());
  const double lateral_m_s = slew_ == SlewMode::kAngular ? lateral * radius_m_ : lateral;
  return radial * radial_ + lateral_m_s * tangential + vertical * Eigen::Vector3d::UnitY();
}

JoystickMapper::JoystickMapper(const JoystickMapping& mapping) noexcept
    : mapping_(mapping), frame_(mapping.frame, mapping.slew, mapping.min_radius_m) {}

Eigen::Vector3d JoystickMapper::map(const GamepadState& pad, const Eigen::Vector3d& tip_m,
                                    double speed_factor) noexcept {
  Eigen::Vector3d op;
  for (std::size_t i = 0; i < kOperatorAxisCount; ++i) {
    const AxisShape& s = mapping_.axes[i];
    op[static_cast<Eigen::Index>(i)] = shape_axis(s, pad.axis(s.axis)) * speed_factor;
  }
  return frame_.to_crane(op, tip_m);
}

Eigen::Vector2d JoystickMapper::drive(const GamepadState& pad) const noexcept {
  Eigen::Vector2d d;
  for (std::size_t i = 0; i < kDriveAxisCount; ++i) {
    const AxisShape& s = mapping_.drive[i];
    d[static_cast<Eigen::Index>(i)] = shape_axis(s, pad.axis(s.axis));
  }
  return d;
}

}  // namespace craneassist::input
