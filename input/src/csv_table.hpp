// The strict numeric CSV reader shared by the input file formats (joint trajectories; the rules
// are those of docs/replay-format.md): '#' comment lines and blank lines anywhere, CRLF accepted,
// a UTF-8 byte-order mark ignored, an exact header line, then rows of finite numbers, one per
// column, the first column a time >= 0 that strictly increases. Errors are ReplayErrors naming
// file, line and column.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "craneassist/input/replay.hpp"

namespace craneassist::input::detail {

struct CsvTable {
  std::vector<std::string> columns;
  std::vector<double> values;      // row-major, columns.size() per row
  std::vector<std::size_t> lines;  // 1-based file line of each row
  std::size_t rows() const { return lines.size(); }
  double at(std::size_t row, std::size_t column) const {
    return values[row * columns.size() + column];
  }
};

// Reads text whose header must be exactly `columns` joined by commas.
CsvTable read_csv_table(std::string_view text, std::string_view source_name,
                        const std::vector<std::string>& columns, std::size_t max_rows);

}  // namespace craneassist::input::detail
