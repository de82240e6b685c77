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

// The name of enumerator i of a name table, "unknown" past its end.
template <std::size_t N>
const char* name_in(const std::array<const char*, N>& names, std::size_t i) {
  return i < N ? names[i] : "unknown";
}

// The enumerator whose name in the table is `name`: true and out set; false (out unchanged) when
// no name matches.
template <class Enum, std::size_t N>
bool parse_name(const std::array<const char*, N>& names, std::string_view name, Enum& out) {
  for (std::size_t i = 0; i < N; ++i) {
    if (name == names[i]) {
      out = static_cast<Enum>(i);
      return true;
    }
  }
  return false;
}

}  // namespace

const char* to_string(GamepadAxis axis) {
  return name_in(kAxisNames, static_cast<std::size_t>(axis));
}

const char* to_string(GamepadButton button) {
  return name_in(kButtonNames, static_cast<std::size_t>(button));
}

bool parse_gamepad_axis(std::string_view name, GamepadAxis& out) {
  return parse_name(kAxisNames, name, out);
}

bool parse_gamepad_button(std::string_view name, GamepadButton& out) {
  return parse_name(kButtonNames, name, out);
}

}  // namespace craneassist::input
