#include "craneassist/input/gamepad.hpp"

namespace craneassist::input {
namespace {

constexpr std::array<const char*, kGamepadAxisCount> kAxisNames = {
    "left_x", "left_y", "right_x", "right_y", "left_trigger", "right_trigger"};
constexpr std::array<const char*, kGamepadButtonCount> kButtonNames = {"a",
                                                                       "b",
                                                                       "x",
                                                                       "y",
                                                                       "back",
                                                                       "guide",
                                                                       "start",
                                                                       "left_stick",
                                                                       "right_stick",
                                                                       "left_shoulder",
                                                                       "right_shoulder",
                                                                       "dpad_up",
                                                                       "dpad_down",
                                                                       "dpad_left",
                                                                       "dpad_right"};

}  // namespace

const char* to_string(GamepadAxis axis) {
  const auto i = static_cast<std::size_t>(axis);
  return i < kAxisNames.size() ? kAxisNames[i] : "unknown";
}

const char* to_string(GamepadButton button) {
  const auto i = static_cast<std::size_t>(button);
  return i < kButtonNames.size() ? kButtonNames[i] : "unknown";
}

bool parse_gamepad_axis(std::string_view name, GamepadAxis& out) {
  for (std::size_t i = 0; i < kAxisNames.size(); ++i) {
    if (name == kAxisNames[i]) {
      out = static_cast<GamepadAxis>(i);
      return true;
    }
  }
  return false;
}

bool parse_gamepad_button(std::string_view name, GamepadButton& out) {
  for (std::size_t i = 0; i < kButtonNames.size(); ++i) {
    if (name == kButtonNames[i]) {
      out = static_cast<GamepadButton>(i);
      return true;
    }
  }
  return false;
}

}  // namespace craneassist::input
