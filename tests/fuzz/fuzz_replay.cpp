// Replay files (input::Replay, docs/replay-format.md): any bytes are either rejected with a
// FileError or give a replay that keeps the format's rules; a parsed replay written back with
// write_replay parses to the same rows bit for bit; the real-time cursor answers any time.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>

#include "craneassist/input/replay.hpp"
#include "fuzz_check.hpp"

using craneassist::input::FileError;
using craneassist::input::Replay;
using craneassist::input::ReplayCursor;
using craneassist::input::ReplayRow;

namespace {

bool same_rows(const ReplayRow& a, const ReplayRow& b) {
  return same_bits(a.t_s, b.t_s) && same_bits(a.v_m_s.x(), b.v_m_s.x()) &&
         same_bits(a.v_m_s.y(), b.v_m_s.y()) && same_bits(a.v_m_s.z(), b.v_m_s.z()) &&
         a.stop == b.stop && a.wait == b.wait && same_bits(a.load_kg, b.load_kg);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  craneassist::input::ReplayLimits limits;
  limits.max_rows = 2000;
  try {
    const Replay replay = Replay::parse(text, "fuzz.csv", limits);
    const auto& rows = replay.rows();
    FUZZ_CHECK(!rows.empty(), "a replay has a row");
    for (std::size_t i = 0; i < rows.size(); ++i) {
      FUZZ_CHECK(std::isfinite(rows[i].t_s) && rows[i].t_s >= 0.0, "time finite, >= 0");
      FUZZ_CHECK(i == 0 || rows[i].t_s > rows[i - 1].t_s, "time strictly increasing");
      FUZZ_CHECK(
          rows[i].v_m_s.allFinite() && rows[i].v_m_s.cwiseAbs().maxCoeff() <= limits.max_speed_m_s,
          "velocity finite, within the limit");
      FUZZ_CHECK(!rows[i].stop || rows[i].v_m_s.isZero(0.0), "a stop row has zero velocity");
    }

    // Written back, it reads the same.
    std::ostringstream out;
    craneassist::input::write_replay(out, rows);
    const Replay again = Replay::parse(out.str(), "written.csv", limits);
    FUZZ_CHECK(again.rows().size() == rows.size(), "round trip keeps the row count");
    for (std::size_t i = 0; i < rows.size(); ++i) {
      FUZZ_CHECK(same_rows(rows[i], again.rows()[i]), "round trip keeps every row bit for bit");
    }

    // The cursor: forward through the rows, then jumps back and beyond, NaN and infinities.
    ReplayCursor cursor(replay);
    for (const ReplayRow& row : rows) {
      const Eigen::Vector3d v = cursor.command_at(row.t_s);
      FUZZ_CHECK(row.stop ? v.hasNaN() : v == row.v_m_s, "a row applies from its own time on");
    }
    const double probes[] = {0.0,
                             -1.0,
                             rows.front().t_s,
                             replay.end_time_s() * 0.5,
                             replay.end_time_s() + 1.0,
                             std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity()};
    for (double t : probes) (void)cursor.command_at(t);
  } catch (const FileError& e) {
    FUZZ_CHECK(e.file() == "fuzz.csv", "the error names the file");
  }
  return 0;
}
