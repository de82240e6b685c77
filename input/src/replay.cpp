#include "craneassist/input/replay.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <ostream>
#include <system_error>

#include "text_fields.hpp"

namespace craneassist::input {
namespace {

// The optional fifth column `stop` (1: the operator input was not valid from this row on).
constexpr std::array<std::string_view, 5> kColumns = {"t", "v_x", "v_y", "v_z", "stop"};
constexpr std::string_view kHeader = "t,v_x,v_y,v_z";
constexpr std::string_view kStopHeader = "t,v_x,v_y,v_z,stop";
constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

using detail::format_number;
using detail::kMaxNumberChars;
using detail::number;
using detail::quoted;
using detail::split_fields;
using detail::trim;

class Parser {
 public:
  Parser(std::string_view source_name, const ReplayLimits& limits)
      : source_(source_name), limits_(limits) {}

  std::vector<ReplayRow> parse(std::string_view text);

 private:
  ReplayError error(std::size_t line, std::string_view field, std::string reason) const {
    return ReplayError(source_, line, std::string(field), std::move(reason));
  }
  double parse_field(std::string_view text, std::size_t line, std::string_view field) const;
  void check_header(std::string_view content, std::size_t line);
  ReplayRow parse_row(std::string_view content, std::size_t line);

  std::string source_;
  ReplayLimits limits_;
  std::size_t columns_ = 4;  // 4, or 5 with the stop column
  std::vector<ReplayRow> rows_;
  std::size_t previous_row_line_ = 0;
};

double Parser::parse_field(std::string_view text, std::size_t line, std::string_view field) const {
  double value = 0.0;
  std::string reason;
  if (!detail::parse_number(text, value, reason)) throw error(line, field, std::move(reason));
  return value;
}

void Parser::check_header(std::string_view content, std::size_t line) {
  std::array<std::string_view, 5> fields;
  const std::size_t count = split_fields(content, fields);
  bool ok = count == 4 || count == 5;
  for (std::size_t i = 0; ok && i < count; ++i) ok = fields[i] == kColumns[i];
  if (!ok) {
    throw error(line, "",
                "expected the header '" + std::string(kHeader) + "' or '" +
                    std::string(kStopHeader) + "', got " + quoted(content));
  }
  columns_ = count;
}

ReplayRow Parser::parse_row(std::string_view content, std::size_t line) {
  std::array<std::string_view, 5> fields;
  const std::size_t count = split_fields(content, fields);
  if (count != columns_) {
    throw error(line, "",
                "expected " + std::to_string(columns_) + " fields (" +
                    std::string(columns_ == 5 ? kStopHeader : kHeader) + "), got " +
                    std::to_string(count));
  }
  if (rows_.size() >= limits_.max_rows) {
    throw error(line, "",
                "too many data rows (limit " + std::to_string(limits_.max_rows) + " rows)");
  }

  ReplayRow row{};
  row.t_s = parse_field(fields[0], line, kColumns[0]);
  if (row.t_s < 0.0) throw error(line, kColumns[0], "negative time: " + quoted(fields[0]));
  if (!rows_.empty() && !(row.t_s > rows_.back().t_s)) {
    throw error(line, kColumns[0],
                "time not strictly increasing: " + number(row.t_s) + " s follows " +
                    number(rows_.back().t_s) + " s (line " + std::to_string(previous_row_line_) +
                    ")");
  }
  for (Eigen::Index i = 0; i < 3; ++i) {
    const auto column = static_cast<std::size_t>(i + 1);
    const double v = parse_field(fields[column], line, kColumns[column]);
    if (std::abs(v) > limits_.max_speed_m_s) {
      throw error(line, kColumns[column],
                  "magnitude of " + number(v) + " m/s exceeds the limit of " +
                      number(limits_.max_speed_m_s) + " m/s");
    }
    row.v_m_s[i] = v;
  }
  if (columns_ == 5) {
    if (fields[4] == "1") {
      row.stop = true;
    } else if (fields[4] != "0") {
      throw error(line, kColumns[4],
                  fields[4].empty() ? std::string("missing value")
                                    : "expected 0 or 1, got " + quoted(fields[4]));
    }
    for (Eigen::Index i = 0; row.stop && i < 3; ++i) {
      if (row.v_m_s[i] != 0.0) {
        const auto column = static_cast<std::size_t>(i + 1);
        throw error(line, kColumns[column],
                    "must be 0 in a stop row (stop = 1), got " + quoted(fields[column]));
      }
    }
  }
  return row;
}

std::vector<ReplayRow> Parser::parse(std::string_view text) {
  if (text.starts_with(kUtf8Bom)) text.remove_prefix(kUtf8Bom.size());
  bool have_header = false;
  std::size_t line = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view raw = text.substr(pos, end - pos);
    pos = end + 1;
    ++line;
    if (!raw.empty() && raw.back() == '\r') raw.remove_suffix(1);
    const std::string_view content = trim(raw);
    if (content.empty() || content.front() == '#') continue;
    if (!have_header) {
      check_header(content, line);
      have_header = true;
    } else {
      rows_.push_back(parse_row(content, line));
      previous_row_line_ = line;
    }
  }
  // Whole-file problems are reported at the last line (line 1 for an empty file).
  const std::size_t last_line = std::max<std::size_t>(line, 1);
  if (!have_header) {
    throw error(last_line, "",
                "missing header '" + std::string(kHeader) +
                    "' (no line other than comments and blank lines)");
  }
  if (rows_.empty()) throw error(last_line, "", "no data rows after the header");
  return std::move(rows_);
}

}  // namespace

// ---------------------------------------------------------------------------------------------

ReplayError::ReplayError(std::string file, std::size_t line, std::string field, std::string reason)
    : std::runtime_error(file + ":" + std::to_string(line) + ": " +
                         (field.empty() ? std::string() : "field '" + field + "': ") + reason),
      file_(std::move(file)),
      line_(line),
      field_(std::move(field)),
      reason_(std::move(reason)) {}

Replay Replay::parse(std::string_view text, std::string_view source_name,
                     const ReplayLimits& limits) {
  if (!(limits.max_speed_m_s >= 0.0)) {
    throw std::invalid_argument("ReplayLimits::max_speed_m_s must be >= 0, got " +
                                number(limits.max_speed_m_s));
  }
  Parser parser(source_name, limits);
  return Replay(parser.parse(text), std::string(source_name));
}

Replay Replay::load_file(const std::filesystem::path& path, const ReplayLimits& limits) {
  const std::string name = path.string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw ReplayError(name, 0, "", "cannot read file: is a directory");
  }
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int open_errno = errno;
    if (!std::filesystem::exists(path, ec) && !ec) {
      throw ReplayError(name, 0, "", "file not found");
    }
    throw ReplayError(
        name, 0, "",
        "cannot open file" +
            (open_errno != 0 ? ": " + std::generic_category().message(open_errno) : std::string()));
  }
  std::string text;
  std::array<char, 1 << 16> buffer{};
  while (in.read(buffer.data(), static_cast<std::streamsize>(buffer.size())) || in.gcount() > 0) {
    text.append(buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw ReplayError(name, 0, "", "read error");
  return parse(text, name, limits);
}

Eigen::Vector3d ReplayCursor::command_at(double t_s) noexcept {
  const std::vector<ReplayRow>& rows = *rows_;
  const auto row_after = [](double t, const ReplayRow& row) { return t < row.t_s; };
  if (std::isnan(t_s)) return Eigen::Vector3d::Zero();
  if (next_ > 0 && rows[next_ - 1].t_s > t_s) {
    // Going back in time: binary search among the rows already passed.
    next_ = static_cast<std::size_t>(
        std::upper_bound(rows.begin(), rows.begin() + static_cast<std::ptrdiff_t>(next_), t_s,
                         row_after) -
        rows.begin());
  } else {
    // Going forward: a few linear steps cover the per-cycle case, a binary search any jump.
    constexpr int kLinearSteps = 4;
    for (int step = 0; next_ < rows.size() && rows[next_].t_s <= t_s; ++step) {
      if (step == kLinearSteps) {
        next_ = static_cast<std::size_t>(
            std::upper_bound(rows.begin() + static_cast<std::ptrdiff_t>(next_), rows.end(), t_s,
                             row_after) -
            rows.begin());
        break;
      }
      ++next_;
    }
  }
  if (next_ == 0) return Eigen::Vector3d::Zero();
  const ReplayRow& row = rows[next_ - 1];
  return row.stop ? Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()) : row.v_m_s;
}

void write_replay(std::ostream& out, const std::vector<ReplayRow>& rows) {
  const bool stop_column =
      std::any_of(rows.begin(), rows.end(), [](const ReplayRow& row) { return row.stop; });
  out << (stop_column ? kStopHeader : kHeader) << '\n';
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
    line += '\n';
    out << line;
  }
}

}  // namespace craneassist::input
