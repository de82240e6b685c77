#include "craneassist/input/tool_path_file.hpp"

#include <sstream>

#include "csv_reader.hpp"

namespace craneassist::input {
namespace {

const detail::CsvFormat& tool_path_format() {
  static const detail::CsvFormat format = [] {
    detail::CsvFormat f;
    f.columns = {{"x", detail::CsvKind::kNumber, ToolPathLimits::kMaxCoordinateM, "m"},
                 {"y", detail::CsvKind::kNumber, ToolPathLimits::kMaxCoordinateM, "m"}};
    f.max_rows = ToolPathLimits::kMaxViaPoints;
    return f;
  }();
  return format;
}

}  // namespace

ToolPathFile parse_tool_path(std::string_view text, std::string_view source_name) {
  ToolPathFile path;
  path.source = std::string(source_name);
  const detail::CsvFile file =
      detail::read_csv(text, source_name, tool_path_format(), [&](const detail::CsvRow& row) {
        const Eigen::Vector2d p(row.values[0], row.values[1]);
        if (!path.via_m.empty()) {
          const double gap = (p - path.via_m.back()).norm();
          if (gap < ToolPathLimits::kMinSpacingM) {
            std::ostringstream why;
            why << "via point " << gap << " m from the one before (line " << path.lines.back()
                << "); at least " << ToolPathLimits::kMinSpacingM << " m apart";
            throw row.error("", why.str());
          }
        }
        path.via_m.push_back(p);
        path.lines.push_back(row.line);
      });
  if (path.via_m.size() < ToolPathLimits::kMinViaPoints) {
    throw FileError(
        path.source, file.last_line, "",
        "a tool path needs at least 2 via points, got " + std::to_string(path.via_m.size()));
  }
  return path;
}

ToolPathFile load_tool_path(const std::filesystem::path& path) {
  return parse_tool_path(detail::read_file_text(path, "tool path"), path.string());
}

}  // namespace craneassist::input
