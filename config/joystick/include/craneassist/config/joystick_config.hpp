// Loading a joystick mapping file (config/joysticks/*.yaml, docs/joystick.md): the gamepad
// mapping, the input monitor's limits and the keyboard's hold times. Strict: unknown fields,
// unknown axis or button names and out-of-range values are errors naming file, line and field.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "craneassist/config/config_error.hpp"
#include "craneassist/input/input_monitor.hpp"
#include "craneassist/input/joystick_mapping.hpp"
#include "craneassist/input/keyboard.hpp"

namespace craneassist::config {

struct JoystickConfig {
  std::string name;
  input::JoystickMapping mapping;
  input::InputMonitorSettings monitor;
  input::KeyboardSettings keyboard;
  std::string source_name;
};

// Both throw ConfigError.
JoystickConfig load_joystick_config(const std::filesystem::path& path);
JoystickConfig parse_joystick_config(std::string_view yaml_text, std::string_view source_name);

// The shipped default, embedded (config/joysticks/gamepad.yaml).
JoystickConfig default_joystick_config();
// The web view's virtual joystick (config/joysticks/web.yaml): the gamepad mapping with a stale
// timeout for a browser over a network connection (250 ms).
JoystickConfig web_joystick_config();
// The drive mode's (sim --drive, docs/mobile.md#live): the right stick drives the wheeled base,
// the left stick moves the tip in the horizontal plane; on a gamepad
// (config/joysticks/gamepad_drive.yaml) and on the web page (config/joysticks/web_drive.yaml,
// web.yaml's input rules).
JoystickConfig drive_joystick_config();
JoystickConfig web_drive_joystick_config();

}  // namespace craneassist::config
