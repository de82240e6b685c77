#include "craneassist/input/replay.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "csv_reader.hpp"
#include "text_fields.hpp"

namespace craneassist::input {
namespace {

using detail::format_number;
using detail::kMaxNumberChars;
using detail::number;

constexpr std::string_view kLoadColumn = "load_kg";
constexpr std::string_view kStopColumn = "stop";
constexpr std::string_view kWaitColumn = "wait";

// t, the velocity components within the speed limit, then the optional columns: `stop` (1: the
// operator input was not valid from this row on), `wait` (1: the run waits at this row for the
// grapple to settle), then `load_kg` (the simulated crane's load from this row on; its range is
// checked by parse, an empty cell is filled in for the reader first).
// optional_stop: a header may leave out `stop` (the format for a file without a header).
detail::CsvFormat replay_format(const ReplayLimits& limits, bool stop, bool load,
                                bool optional_stop = false, bool wait = false) {
  detail::CsvFormat format;
  format.columns = {{"t", detail::CsvKind::kTime},
                    {"v_x", detail::CsvKind::kNumber, limits.max_speed_m_s, "m/s"},
                    {"v_y", detail::CsvKind::kNumber, limits.max_speed_m_s, "m/s"},
                    {"v_z", detail::CsvKind::kNumber, limits.max_speed_m_s, "m/s"}};
  if (stop) format.columns.emplace_back(std::string(kStopColumn), detail::CsvKind::kFlag);
  if (wait) format.columns.emplace_back(std::string(kWaitColumn), detail::CsvKind::kFlag);
  if (load) format.columns.emplace_back(std::string(kLoadColumn), detail::CsvKind::kNumber);
  format.optional_columns = stop && optional_stop ? 1 : 0;
  format.max_rows = limits.max_rows;
  return format;
}

// The 1-based number of the line of text that `part` (a view into text) starts on.
std::size_t line_of(std::string_view text, std::string_view part) {
  const auto offset = static_cast<std::size_t>(part.data() - text.data());
  return 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + offset, '\n'));
}

// The column of this name in the format (npos when it has none).
std::size_t column_index(const detail::CsvFormat& format, std::string_view name) {
  for (std::size_t i = 0; i < format.columns.size(); ++i) {
    if (format.columns[i].name == name) return i;
  }
  return std::string_view::npos;
}

// The format of a file's header (the first line that is neither blank nor a comment): one of
// t,v_x,v_y,v_z[,stop][,wait][,load_kg], names trimmed and compared exactly as the CSV reader
// does.
// Throws FileError at the header's line for any other header. Without a header: the format whose
// missing-header error the reader gives.
detail::CsvFormat format_of_header(std::string_view text, std::string_view source_name,
                                   const ReplayLimits& limits) {
  const std::string_view header = detail::header_line(text);
  if (header.empty()) return replay_format(limits, true, false, true);
  std::vector<std::string_view> names;
  for (std::string_view rest = header;;) {
    const std::size_t comma = rest.find(',');
    names.push_back(detail::trim(rest.substr(0, comma)));
    if (comma == std::string_view::npos) break;
    rest.remove_prefix(comma + 1);
  }
  for (const bool load : {false, true}) {
    for (const bool wait : {false, true}) {
      for (const bool stop : {false, true}) {
        const detail::CsvFormat format = replay_format(limits, stop, load, false, wait);
        const std::vector<detail::CsvColumn>& columns = format.columns;
        if (std::equal(names.begin(), names.end(), columns.begin(), columns.end(),
                       [](std::string_view name, const detail::CsvColumn& column) {
                         return name == column.name;
                       })) {
          return format;
        }
      }
    }
  }
  throw FileError(std::string(source_name), line_of(text, header), "",
                  "expected the header 't,v_x,v_y,v_z', then any of the columns 'stop', 'wait' "
                  "and 'load_kg' in this order (at most 't,v_x,v_y,v_z,stop,wait,load_kg'), got " +
                      detail::quoted(header));
}

// The CSV reader wants a number in every field, but an empty load_kg cell is allowed (the load
// stays what it was). load_kg is the last column, so such a row (with as many fields as the header,
// `columns`) ends in a comma: the text returned has a 0 after that comma (line numbers unchanged),
// and empty[i] is set for the i-th data row. Rows with another field count are left to the reader.
// Returns an empty string when no cell is empty (then the text is read as it is).
std::string fill_empty_load_cells(std::string_view text, std::size_t columns,
                                  std::vector<bool>& empty) {
  const std::string_view header = detail::header_line(text);
  std::string filled;
  std::size_t copied = 0;  // text before this offset is in filled
  std::size_t pos = static_cast<std::size_t>(header.data() - text.data()) + header.size();
  pos = std::min(text.find('\n', pos), text.size()) + 1;  // the line after the header
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view raw = text.substr(pos, end - pos);
    const std::size_t line_start = pos;
    pos = end + 1;
    if (raw.ends_with('\r')) raw.remove_suffix(1);  // one '\r', as the reader
    const std::string_view content = detail::trim(raw);
    if (content.empty() || content.front() == '#') continue;  // comment or blank
    const bool is_empty =
        content.back() == ',' &&
        static_cast<std::size_t>(std::count(content.begin(), content.end(), ',')) + 1 == columns;
    empty.push_back(is_empty);
    if (!is_empty) continue;
    const std::size_t after_comma = line_start + raw.rfind(',') + 1;
    filled.append(text.substr(copied, after_comma - copied)).append("0");
    copied = after_comma;
  }
  if (copied > 0) filled.append(text.substr(copied));
  return filled;
}

// The rows' load in effect from each row's time on (ReplayCursor::load_at); empty without loads.
std::vector<double> effective_loads(const std::vector<ReplayRow>& rows) {
  const bool any = std::any_of(rows.begin(), rows.end(),
                               [](const ReplayRow& row) { return !std::isnan(row.load_kg); });
  std::vector<double> loads;
  if (!any) return loads;
  loads.reserve(rows.size());
  double load = std::numeric_limits<double>::quiet_NaN();
  for (const ReplayRow& row : rows) {
    if (!std::isnan(row.load_kg)) load = row.load_kg;
    loads.push_back(load);
  }
  return loads;
}

// The number of rows with time <= t_s (not NaN), from the count `next` for an earlier query: a
// few linear steps cover the per-cycle case, a binary search a jump or a step back.
std::size_t rows_up_to(const std::vector<ReplayRow>& rows, std::size_t next, double t_s) noexcept {
  const auto row_after = [](double t, const ReplayRow& row) { return t < row.t_s; };
  if (next > 0 && rows[next - 1].t_s > t_s) {
    // Going back in time: binary search among the rows already passed.
    return static_cast<std::size_t>(
        std::upper_bound(rows.begin(), rows.begin() + static_cast<std::ptrdiff_t>(next), t_s,
                         row_after) -
        rows.begin());
  }
  // Going forward: a few linear steps cover the per-cycle case, a binary search any jump.
  constexpr int kLinearSteps = 4;
  for (int step = 0; next < rows.size() && rows[next].t_s <= t_s; ++step) {
    if (step == kLinearSteps) {
      return static_cast<std::size_t>(
          std::upper_bound(rows.begin() + static_cast<std::ptrdiff_t>(next), rows.end(), t_s,
                           row_after) -
          rows.begin());
    }
    ++next;
  }
  return next;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

Replay Replay::parse(std::string_view text, std::string_view source_name,
                     const ReplayLimits& limits) {
  if (!(limits.max_speed_m_s >= 0.0)) {
    throw std::invalid_argument("ReplayLimits::max_speed_m_s must be >= 0, got " +
                                number(limits.max_speed_m_s));
  }
  const detail::CsvFormat format = format_of_header(text, source_name, limits);
  const std::size_t columns = format.columns.size();
  const std::size_t stop_column = column_index(format, kStopColumn);
  const std::size_t wait_column = column_index(format, kWaitColumn);
  const bool load_column = column_index(format, kLoadColumn) != std::string_view::npos;
  std::vector<bool> empty_load;  // per data row: its load_kg cell is empty
  const std::string filled = load_column ? fill_empty_load_cells(text, columns, empty_load) : "";
  std::vector<ReplayRow> rows;
  detail::read_csv(
      filled.empty() ? text : filled, source_name, format, [&](const detail::CsvRow& row) {
        ReplayRow r{row.values[0], {row.values[1], row.values[2], row.values[3]}};
        r.stop = stop_column < columns && row.values[stop_column] == 1.0;
        r.wait = wait_column < columns && row.values[wait_column] == 1.0;
        for (std::size_t i = 1; r.stop && i <= 3; ++i) {
          if (row.values[i] != 0.0) {
            throw row.error(format.columns[i].name, "must be 0 in a stop row (stop = 1), got " +
                                                        detail::quoted(row.text[i]));
          }
        }
        if (load_column && !empty_load[rows.size()]) {
          const double load = row.values[columns - 1];
          if (!(load >= 0.0 && load <= kMaxLoad_kg)) {
            static_assert(kMaxLoad_kg == 100000.0, "the message names the limit");
            throw row.error(kLoadColumn, "must be between 0 and 100000 kg, got " +
                                             detail::quoted(row.text[columns - 1]));
          }
          r.load_kg = load;
        }
        rows.push_back(r);
      });
  return Replay(std::move(rows), std::string(source_name));
}

Replay::Replay(std::vector<ReplayRow> rows, std::string source_name)
    : rows_(std::move(rows)),
      loads_kg_(effective_loads(rows_)),
      source_name_(std::move(source_name)) {}

bool Replay::has_waits() const noexcept {
  return std::any_of(rows_.begin(), rows_.end(), [](const ReplayRow& row) { return row.wait; });
}

Replay Replay::load_file(const std::filesystem::path& path, const ReplayLimits& limits) {
  return parse(detail::read_file_text(path, "replay"), path.string(), limits);
}

Eigen::Vector3d ReplayCursor::command_at(double t_s) noexcept {
  if (std::isnan(t_s)) return Eigen::Vector3d::Zero();
  next_ = rows_up_to(*rows_, next_, t_s);
  if (next_ == 0) return Eigen::Vector3d::Zero();
  const ReplayRow& row = (*rows_)[next_ - 1];
  return row.stop ? Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()) : row.v_m_s;
}

double ReplayCursor::load_at(double t_s) noexcept {
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  if (loads_kg_->empty() || std::isnan(t_s)) return kNone;
  load_next_ = rows_up_to(*rows_, load_next_, t_s);
  return load_next_ == 0 ? kNone : (*loads_kg_)[load_next_ - 1];
}

void write_replay(std::ostream& out, const std::vector<ReplayRow>& rows) {
  const bool stop_column =
      std::any_of(rows.begin(), rows.end(), [](const ReplayRow& row) { return row.stop; });
  const bool wait_column =
      std::any_of(rows.begin(), rows.end(), [](const ReplayRow& row) { return row.wait; });
  const bool load_column = std::any_of(
      rows.begin(), rows.end(), [](const ReplayRow& row) { return !std::isnan(row.load_kg); });
  out << detail::csv_header(replay_format({}, stop_column, load_column, false, wait_column))
      << '\n';
  std::array<char, kMaxNumberChars> buffer{};
  std::string line;
  for (const ReplayRow& row : rows) {
    line.clear();
    line += format_number(row.t_s, buffer);
    for (Eigen::Index i = 0; i < 3; ++i) {
      line += ',';
      line += format_number(row.v_m_s[i], buffer);
    }
    if (stop_column) line += row.stop ? ",1" : ",0";
    if (wait_column) line += row.wait ? ",1" : ",0";
    if (load_column) {
      line += ',';
      if (!std::isnan(row.load_kg)) line += format_number(row.load_kg, buffer);
    }
    line += '\n';
    out << line;
  }
}

}  // namespace craneassist::input
