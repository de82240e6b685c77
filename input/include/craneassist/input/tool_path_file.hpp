// The tool-path file of the mobile crane (docs/mobile.md#tool-path-files): the via points, in
// the world's ground plane, through which the tool's composite C2 cubic Bezier path runs
// ("Flow-limited path-following control of a double Ackermann steered hydraulic mobile
// manipulator", section IV). The same text rules as the tip-path files (docs/path-format.md),
// the header `x,y`, no time column: the time law is the controller's.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "craneassist/input/file_error.hpp"

namespace craneassist::input {

struct ToolPathLimits {
  static constexpr std::size_t kMinViaPoints = 2;
  static constexpr std::size_t kMaxViaPoints = 10000;
  static constexpr double kMaxCoordinateM = 10000.0;
  static constexpr double kMinSpacingM = 0.01;  // consecutive via points at least this far apart
};

struct ToolPathFile {
  std::string source;                  // the file's name, for the errors found later
  std::vector<Eigen::Vector2d> via_m;  // world x, y
  std::vector<std::size_t> lines;      // the file line of each via point
};

// Throws FileError naming file, line and field.
ToolPathFile parse_tool_path(std::string_view text, std::string_view source_name);
ToolPathFile load_tool_path(const std::filesystem::path& path);

}  // namespace craneassist::input
