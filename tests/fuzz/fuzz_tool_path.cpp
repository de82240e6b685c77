// Tool-path files of the mobile crane (input::parse_tool_path, docs/mobile.md#tool-path-files):
// any bytes are rejected with a FileError naming the file, or give via points that keep the
// rules; the composite Bezier path through them and the platform's offset path are finite
// everywhere, and the check `craneassist research follow` runs before it moves (cusp, steering
// limit) gives a finite verdict.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string_view>

#include "craneassist/input/tool_path_file.hpp"
#include "craneassist/paths/planar_path.hpp"
#include "fuzz_check.hpp"

using craneassist::input::FileError;
using craneassist::input::ToolPathFile;
using craneassist::input::ToolPathLimits;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  ToolPathFile file;
  try {
    file = craneassist::input::parse_tool_path(text, "fuzz.csv");
  } catch (const FileError& e) {
    FUZZ_CHECK(e.file() == "fuzz.csv", "the error names the file");
    FUZZ_CHECK(e.line() >= 0, "a line number");
    return 0;
  }
  const auto& via = file.via_m;
  FUZZ_CHECK(
      via.size() >= ToolPathLimits::kMinViaPoints && via.size() <= ToolPathLimits::kMaxViaPoints,
      "the via point count within the limits");
  FUZZ_CHECK(file.lines.size() == via.size(), "a line for every via point");
  for (std::size_t i = 0; i < via.size(); ++i) {
    FUZZ_CHECK(
        via[i].allFinite() && via[i].cwiseAbs().maxCoeff() <= ToolPathLimits::kMaxCoordinateM,
        "coordinates finite, within the limit");
    FUZZ_CHECK(i == 0 || (via[i] - via[i - 1]).norm() >= ToolPathLimits::kMinSpacingM,
               "consecutive via points at least the minimum apart");
    FUZZ_CHECK(i == 0 || file.lines[i] > file.lines[i - 1], "lines increase");
  }

  const craneassist::paths::CompositeBezierPath path(via);
  FUZZ_CHECK(path.segments() == static_cast<int>(via.size()) - 1, "a segment between via points");
  FUZZ_CHECK(std::isfinite(path.length_m()) && path.length_m() > 0.0, "a finite, positive length");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  craneassist::paths::CompositeBezierPath::Point point;
  for (double s : {0.0, 0.125, 0.5, 0.999, 1.0, -1.0, 2.0, nan}) {
    path.evaluate(s, point);
    FUZZ_CHECK(point.p.allFinite() && point.d1.allFinite() && point.d2.allFinite(),
               "the path and its derivatives are finite");
  }
  path.evaluate(0.0, point);
  FUZZ_CHECK((point.p - via.front()).norm() <= 1e-9 * (1.0 + via.front().norm()),
             "the path starts at the first via point");
  path.evaluate(1.0, point);
  FUZZ_CHECK((point.p - via.back()).norm() <= 1e-9 * (1.0 + via.back().norm()),
             "the path ends at the last via point");

  // What `follow` checks before it moves, on both sides of the path.
  for (double offset : {4.5, -4.5}) {
    const auto check = craneassist::paths::check_offset_path(path, offset, 400);
    FUZZ_CHECK(!std::isinf(check.min_v_prime_m), "the lowest v' is finite or NaN");
    FUZZ_CHECK(std::isfinite(check.max_curvature_1_m) && check.max_curvature_1_m >= 0.0,
               "the sharpest turn is finite");
    FUZZ_CHECK(check.min_v_prime_s >= 0.0 && check.min_v_prime_s <= 1.0 &&
                   check.max_curvature_s >= 0.0 && check.max_curvature_s <= 1.0,
               "the places lie on the path");
  }
  return 0;
}
