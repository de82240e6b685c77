// Replay files: recorded tip-velocity commands (CSV), their strict reader, a real-time cursor for
// per-cycle lookup and a writer. The format is specified in docs/replay-format.md.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "craneassist/input/file_error.hpp"

namespace craneassist::input {

// One command: from time t_s on, the tip velocity command is v_m_s (crane frame: x forward, y up,
// z lateral), held until the next row's time (zero-order hold). stop: the operator input was not
// valid from t_s on (the file's optional `stop` column); v_m_s is then zero and the loop gives the
// controller a non-finite command: a jerk-limited stop, then neutral valves. load_kg: the mass in
// the simulated crane's grapple from t_s on (the file's optional `load_kg` column); NaN when this
// row does not set it (an empty cell: the load stays what it was). wait: a scripted operator's
// pause (the file's optional `wait` column): the run holds this row's command until the hanging
// grapple has settled, and every later row comes that much later (control::ReplayInput;
// docs/replay-format.md).
struct ReplayRow {
  double t_s;
  Eigen::Vector3d v_m_s;
  bool stop = false;
  double load_kg = std::numeric_limits<double>::quiet_NaN();
  bool wait = false;
};

// Sanity limits enforced while reading.
struct ReplayLimits {
  double max_speed_m_s = 5.0;         // maximum magnitude of each velocity component
  std::size_t max_rows = 10'000'000;  // maximum number of data rows
};

// A validated replay: at least one row, times finite, >= 0 and strictly increasing, velocity
// components finite and within the limits, zero in stop rows, loads NaN or in [0, kMaxLoad_kg].
class Replay {
 public:
  // The largest load_kg accepted (equal is accepted): the range of --payload.
  static constexpr double kMaxLoad_kg = 100000.0;

  // Reads and validates a file; the source name in errors is path.string(). Throws FileError
  // (the field is the column: "t", "v_x", "v_y", "v_z", "stop", "wait", "load_kg"), and
  // std::invalid_argument if limits.max_speed_m_s is negative or NaN.
  static Replay load_file(const std::filesystem::path& path, const ReplayLimits& limits = {});
  // Validates text in the replay format; source_name is used in error messages. Throws as
  // load_file.
  static Replay parse(std::string_view text, std::string_view source_name,
                      const ReplayLimits& limits = {});

  const std::vector<ReplayRow>& rows() const noexcept { return rows_; }
  // Time of the last row.
  double end_time_s() const noexcept { return rows_.back().t_s; }
  std::string_view source_name() const noexcept { return source_name_; }
  // Some row sets a load (the file has a load_kg column with at least one number in it).
  bool has_load() const noexcept { return !loads_kg_.empty(); }
  // Some row waits for the grapple to settle (the file's wait column).
  bool has_waits() const noexcept;

 private:
  friend class ReplayCursor;

  Replay(std::vector<ReplayRow> rows, std::string source_name);

  std::vector<ReplayRow> rows_;
  // Per row, the load in effect from its time on: the load_kg of the last row up to it that sets
  // one, NaN before the first. Empty when no row sets a load.
  std::vector<double> loads_kg_;
  std::string source_name_;
};

// Zero-order-hold lookup for the real-time loop: no exceptions, no allocation. O(1) amortised for
// non-decreasing query times; any other query (going back, jumping ahead) costs O(log n).
// Keeps a reference to the replay's rows: the Replay must outlive the cursor and stay unmodified.
class ReplayCursor {
 public:
  explicit ReplayCursor(const Replay& replay) noexcept
      : rows_(&replay.rows_), loads_kg_(&replay.loads_kg_) {}

  // Velocity of the last row with t_s <= query (a row applies from exactly its own time on); zero
  // before the first row's time and for a NaN query; the last row's value after the last row.
  // A stop row gives a quiet-NaN vector (what the live loop gives the controller on an input
  // fault: the controller's jerk-limited stop, then neutral valves).
  Eigen::Vector3d command_at(double t_s) noexcept;

  // The load set by the last row with t_s <= query that sets one (rows with an empty load_kg cell
  // keep it); NaN before the first such row, when no row sets a load, and for a NaN query. Same
  // cost as command_at and independent of it (both may be called each cycle with the same time).
  double load_at(double t_s) noexcept;

 private:
  const std::vector<ReplayRow>* rows_;
  const std::vector<double>* loads_kg_;
  // Number of rows with time <= the last query time, i.e. the active row is next_ - 1: one for
  // command_at, one for load_at.
  std::size_t next_ = 0;
  std::size_t load_next_ = 0;
};

// Writes the header and rows in the replay format ('\n' line endings, shortest round-trip number
// form): parse() reads them back bit-exactly. The stop column is written only when some row has
// stop set, the wait column only when some row waits, the load_kg column (last; an empty cell for
// a NaN load) only when some row has a
// load, so a file without either keeps the 4-column form. Does not validate; rows that break the
// rules (e.g. non-increasing times) produce a file that parse() rejects.
void write_replay(std::ostream& out, const std::vector<ReplayRow>& rows);

}  // namespace craneassist::input
