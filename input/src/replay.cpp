#include "craneassist/input/replay.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <ostream>
#include <stdexcept>

#include "csv_reader.hpp"
#include "text_fields.hpp"

namespace craneassist::input {
namespace {

using detail::format_number;
using detail::kMaxNumberChars;
using detail::number;

// t, the velocity components within the speed limit and the optional fifth column `stop` (1: the
// operator input was not valid from this row on).
detail::CsvFormat replay_format(const ReplayLimits& limits) {
  detail::CsvFormat format;
  format.columns = {{"t", detail::CsvKind::kTime},
                    {"v_x", detail::CsvKind::kNumber, limits.max_speed_m_s, "m/s"},
                    {"v_y", detail::CsvKind::kNumber, limits.max_speed_m_s, "m/s"},
                    {"v_z", detail::CsvKind::kNumber, limits.max_speed_m_s, "m/s"},
                    {"stop", detail::CsvKind::kFlag}};
  format.optional_columns = 1;
  format.max_rows = limits.max_rows;
  return format;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

Replay Replay::parse(std::string_view text, std::string_view source_name,
                     const ReplayLimits& limits) {
  if (!(limits.max_speed_m_s >= 0.0)) {
    throw std::invalid_argument("ReplayLimits::max_speed_m_s must be >= 0, got " +
                                number(limits.max_speed_m_s));
  }
  const detail::CsvFormat format = replay_format(limits);
  std::vector<ReplayRow> rows;
  detail::read_csv(text, source_name, format, [&](const detail::CsvRow& row) {
    ReplayRow r{row.values[0], {row.values[1], row.values[2], row.values[3]}, false};
    r.stop = row.values.size() == 5 && row.values[4] == 1.0;
    for (std::size_t i = 1; r.stop && i <= 3; ++i) {
      if (row.values[i] != 0.0) {
        throw row.error(format.columns[i].name,
                        "must be 0 in a stop row (stop = 1), got " + detail::quoted(row.text[i]));
      }
    }
    rows.push_back(r);
  });
  return Replay(std::move(rows), std::string(source_name));
}

Replay Replay::load_file(const std::filesystem::path& path, const ReplayLimits& limits) {
  return parse(detail::read_file_text(path, "replay"), path.string(), limits);
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
  out << detail::csv_header(replay_format({}), stop_column ? 5 : 4) << '\n';
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
