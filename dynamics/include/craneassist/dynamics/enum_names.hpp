// Enum values by name, for the config files and the command line. Each such enum spells its names
// once, in its to_string(), and lists its values in an array beside it (dynamics::kPumpModes,
// config::kBackendKinds, ...); its parse function, the choices of a command-line option and the
// alternatives in a message all come from these two.
//
// In dynamics because every module that names enum values (config, scaling, planner, app) sees
// it. Plain C++17: the DDS module includes config headers that use it.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace craneassist {

// The value whose to_string() (found by argument-dependent lookup) is text; nullopt when none.
template <typename Enum, std::size_t N>
std::optional<Enum> parse_name(const std::array<Enum, N>& values, std::string_view text) {
  for (const Enum value : values) {
    if (text == to_string(value)) return value;
  }
  return std::nullopt;
}

// The names of the values, in order: e.g. a command-line option's CLI::IsMember list.
template <typename Enum, std::size_t N>
std::vector<std::string> names_of(const std::array<Enum, N>& values) {
  std::vector<std::string> names;
  for (const Enum value : values) names.emplace_back(to_string(value));
  return names;
}

// The names joined for a message: "a, b or c".
template <typename Enum, std::size_t N>
std::string alternatives(const std::array<Enum, N>& values) {
  std::string text;
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) text += i + 1 == N ? " or " : ", ";
    text += to_string(values[i]);
  }
  return text;
}

}  // namespace craneassist
