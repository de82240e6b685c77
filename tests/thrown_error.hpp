// The error a call throws, for the tests of rejected files and settings (input::FileError,
// config::ConfigError): test_replay.cpp, test_prescribed_path.cpp, test_input_files.cpp,
// test_config.cpp, test_can_mapping.cpp, test_valve_table.cpp, test_joystick_config.cpp and
// test_scenario_suite.cpp.
#pragma once

#include <gtest/gtest.h>

#include <string>

namespace craneassist::test {

// The Error that call() throws. When it throws none: a test failure with the message `accepted`
// (what was accepted), and an empty Error ("", line 0, "", "").
template <class Error, class Call>
Error thrown_error(Call&& call, const std::string& accepted) {
  try {
    call();
  } catch (const Error& e) {
    return e;
  }
  ADD_FAILURE() << accepted;
  return Error("", 0, "", "");
}

}  // namespace craneassist::test
