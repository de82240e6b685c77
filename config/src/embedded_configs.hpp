#pragma once

namespace craneassist::config::embedded {

extern const char* const kK70mYaml;
extern const char* const kPlanar2rYaml;
extern const char* const kMhsb3linkYaml;
extern const char* const kGamepadYaml;
extern const char* const kWebJoystickYaml;
extern const char* const kGamepadDriveYaml;
extern const char* const kWebDriveJoystickYaml;
extern const char* const kTelemetryYaml;
extern const char* const kMobileBaseYaml;

}  // namespace craneassist::config::embedded
