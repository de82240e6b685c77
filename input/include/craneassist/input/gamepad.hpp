// The state of a gamepad in the SDL GameController layout (Xbox naming): what the physical
// joystick back ends (evdev, SDL2) produce and the joystick mapping reads. Sticks are -1..1
// (x right, y down, as the devices report them), triggers 0..1, buttons pressed or not.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

namespace craneassist::input {

enum class GamepadAxis { kLeftX, kLeftY, kRightX, kRightY, kLeftTrigger, kRightTrigger };
inline constexpr std::size_t kGamepadAxisCount = 6;

enum class GamepadButton {
  kA,
  kB,
  kX,
  kY,
  kBack,
  kGuide,
  kStart,
  kLeftStick,
  kRightStick,
  kLeftShoulder,
  kRightShoulder,
  kDpadUp,
  kDpadDown,
  kDpadLeft,
  kDpadRight,
};
inline constexpr std::size_t kGamepadButtonCount = 15;

struct GamepadState {
  std::array<double, kGamepadAxisCount> axes{};
  std::array<bool, kGamepadButtonCount> buttons{};

  double axis(GamepadAxis a) const { return axes[static_cast<std::size_t>(a)]; }
  bool button(GamepadButton b) const { return buttons[static_cast<std::size_t>(b)]; }
  void set_axis(GamepadAxis a, double v) { axes[static_cast<std::size_t>(a)] = v; }
  void set_button(GamepadButton b, bool pressed) { buttons[static_cast<std::size_t>(b)] = pressed; }
};

// Config names: left_x, left_y, right_x, right_y, left_trigger, right_trigger; a, b, x, y, back,
// guide, start, left_stick, right_stick, left_shoulder, right_shoulder, dpad_up, dpad_down,
// dpad_left, dpad_right. parse_* return false for an unknown name.
const char* to_string(GamepadAxis axis);
const char* to_string(GamepadButton button);
bool parse_gamepad_axis(std::string_view name, GamepadAxis& out);
bool parse_gamepad_button(std::string_view name, GamepadButton& out);

}  // namespace craneassist::input
