// The strict CSV reader of the input file formats: replays (docs/replay-format.md), prescribed
// paths (docs/path-format.md) and joint trajectories (docs/trajectory-format.md). One set of rules
// for all three: '#' comment lines and blank lines anywhere, CRLF accepted, a UTF-8 byte-order
// mark ignored, an exact header line (the format's columns, the last few of them optional), then
// rows of as many fields, each a finite number (or 0/1 in a flag column), a time column >= 0 and
// strictly increasing, a row limit. Every error is a FileError naming file, line and field.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "craneassist/input/file_error.hpp"

namespace craneassist::input::detail {

// The latest time a file may hold (a time column's bound): one day. A run is as long as its file;
// this keeps a two-row file from running for months and filling the disk with its log.
inline constexpr double kMaxFileTime_s = 86400.0;

enum class CsvKind {
  kTime,    // a finite number in [0, kMaxFileTime_s], strictly increasing from row to row
  kNumber,  // a finite number
  kFlag,    // 0 or 1
};

struct CsvColumn {
  CsvColumn(std::string name_, CsvKind kind_ = CsvKind::kNumber,
            double limit_ = std::numeric_limits<double>::infinity(), std::string unit_ = {})
      : name(std::move(name_)), kind(kind_), limit(limit_), unit(std::move(unit_)) {}

  std::string name;
  CsvKind kind;
  // kNumber: the largest magnitude accepted (equal is accepted), with its unit for the message.
  double limit;
  std::string unit;
};

struct CsvFormat {
  std::vector<CsvColumn> columns;    // the full header, in order
  std::size_t optional_columns = 0;  // how many of the last columns a header may leave out
  std::size_t max_rows = 0;          // data rows at most
  double min_time_step_s = 0.0;      // kTime: consecutive times at least this far apart
};

// One data row as the reader passed it: every field checked against its column.
struct CsvRow {
  std::string_view source;
  std::size_t line = 0;                    // 1-based file line
  std::span<const double> values;          // one per column of the header read; a flag 0 or 1
  std::span<const std::string_view> text;  // the fields as written, trimmed

  // A FileError at this row (field: a column name, or empty).
  FileError error(std::string_view field, std::string reason) const;
};

struct CsvFile {
  std::size_t columns = 0;            // columns in the header read
  std::size_t rows = 0;               // data rows (at least 1)
  std::size_t header_line = 0;        // the header's line
  std::size_t last_line = 1;          // the line whole-file problems are reported at
  std::vector<std::string> comments;  // the comment lines, without '#' and one space after it
};

// Reads text in the given format and calls on_row for each data row in order (on_row may throw
// a row.error() for a rule of its own). source_name names the file in errors. Throws FileError.
CsvFile read_csv(std::string_view text, std::string_view source_name, const CsvFormat& format,
                 const std::function<void(const CsvRow&)>& on_row);

// The header of the first `columns` columns of a format (all when npos): "t,x,y,z".
std::string csv_header(const CsvFormat& format, std::size_t columns = std::string::npos);

// The header line as read_csv sees it: the first line that is neither blank nor a comment,
// trimmed; empty when there is none.
std::string_view header_line(std::string_view text);

// The contents of a file, at most files::kMaxCsvBytes (64 MiB): the bounded read of
// craneassist/files/text_file.hpp. Throws FileError at line 0 when it cannot be read ("file not
// found", "cannot open file: REASON", "cannot read file: is a directory", "read error: REASON")
// or is larger ("larger than 64 MiB (the limit for replay files)"; `kind` names the format).
std::string read_file_text(const std::filesystem::path& path, std::string_view kind);

}  // namespace craneassist::input::detail
