#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "allocation_counter.hpp"
#include "craneassist/input/replay.hpp"
#include "file_error_checks.hpp"
#include "thrown_error.hpp"

namespace craneassist::input {
namespace {

// The query times a cursor meets, 20000 of them: random jumps either way, exact row times, and
// the small forward steps of a control loop. rows end before t_end.
std::vector<double> cursor_queries(const std::vector<ReplayRow>& rows, double t_end,
                                   std::mt19937_64& rng) {
  std::uniform_real_distribution<double> any_time(-1.0, t_end + 1.0);
  std::uniform_int_distribution<std::size_t> any_row(0, rows.size() - 1);
  std::uniform_real_distribution<double> step(0.0, 0.05);
  std::vector<double> queries;
  double q = -0.1;
  for (int i = 0; i < 20000; ++i) {
    const int kind = i % 7;
    if (kind == 0) {
      q = any_time(rng);  // random jump, either direction
    } else if (kind == 1) {
      q = rows[any_row(rng)].t_s;  // exactly on a row time
    } else {
      q += step(rng);  // typical control-loop progression
    }
    queries.push_back(q);
  }
  return queries;
}

namespace fs = std::filesystem;

constexpr const char* kSource = "bad_replay.csv";

// Parses text that must be rejected; returns the error for further checks.
FileError parse_error(std::string_view text, const ReplayLimits& limits = {}) {
  return test::thrown_error<FileError>([&] { Replay::parse(text, kSource, limits); },
                                       "accepted:\n" + std::string(text));
}

// Checks line, field, that the reason contains reason_part, and the what() layout.
void expect_rejected(std::string_view text, std::size_t line, std::string_view field,
                     std::string_view reason_part, const ReplayLimits& limits = {}) {
  SCOPED_TRACE(std::string("text:\n") + std::string(text));
  test::expect_file_error(parse_error(text, limits), kSource, line, field, reason_part);
}

void expect_vec(const Eigen::Vector3d& actual, double x, double y, double z) {
  EXPECT_EQ(actual.x(), x);
  EXPECT_EQ(actual.y(), y);
  EXPECT_EQ(actual.z(), z);
}

// A temporary file removed at scope exit.
class TempFile {
 public:
  explicit TempFile(std::string_view contents) {
    path_ = fs::temp_directory_path() /
            ("craneassist_test_replay_" + std::to_string(std::random_device{}()) + ".csv");
    std::ofstream out(path_, std::ios::binary);
    out << contents;
  }
  ~TempFile() {
    std::error_code ec;
    fs::remove(path_, ec);
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// ---- accepted input --------------------------------------------------------------------------

TEST(ReplayParse, MinimalFile) {
  const Replay r = Replay::parse("t,v_x,v_y,v_z\n0,0.1,-0.2,0.3\n", "min.csv");
  ASSERT_EQ(r.rows().size(), 1u);
  EXPECT_EQ(r.rows()[0].t_s, 0.0);
  expect_vec(r.rows()[0].v_m_s, 0.1, -0.2, 0.3);
  EXPECT_EQ(r.end_time_s(), 0.0);
  EXPECT_EQ(r.source_name(), "min.csv");
}

TEST(ReplayParse, CommentsBlankLinesAndWhitespace) {
  const Replay r = Replay::parse(
      "# recorded 2024-05-01\n"
      "\n"
      "   \t\n"
      "  # indented comment\n"
      " t , v_x,\tv_y ,v_z \n"
      "# between rows\n"
      "0, 0.5, 0, 0\n"
      "\n"
      "  1.5 ,0,  0.25,-1e-1\t\n"
      "2,0,0,0",  // no final newline
      "c.csv");
  ASSERT_EQ(r.rows().size(), 3u);
  EXPECT_EQ(r.rows()[1].t_s, 1.5);
  expect_vec(r.rows()[1].v_m_s, 0.0, 0.25, -0.1);
  EXPECT_EQ(r.end_time_s(), 2.0);
}

TEST(ReplayParse, WindowsLineEndingsAndByteOrderMark) {
  const Replay r = Replay::parse(
      "\xEF\xBB\xBF# exported\r\nt,v_x,v_y,v_z\r\n\r\n0,1,0,0\r\n3,0,0,0\r\n", "w.csv");
  ASSERT_EQ(r.rows().size(), 2u);
  expect_vec(r.rows()[0].v_m_s, 1.0, 0.0, 0.0);
  EXPECT_EQ(r.end_time_s(), 3.0);
}

TEST(ReplayParse, FirstRowMayStartLaterThanZeroAndSpeedAtLimitIsAccepted) {
  const Replay r = Replay::parse("t,v_x,v_y,v_z\n2.5,5,-5,0\n", "x");
  EXPECT_EQ(r.rows()[0].t_s, 2.5);
  expect_vec(r.rows()[0].v_m_s, 5.0, -5.0, 0.0);
  // Negative zero is not a negative time.
  EXPECT_NO_THROW(Replay::parse("t,v_x,v_y,v_z\n-0,0,0,0\n", "x"));
}

TEST(ReplayParse, RowLimitReachedExactlyIsAccepted) {
  ReplayLimits limits;
  limits.max_rows = 2;
  EXPECT_EQ(Replay::parse("t,v_x,v_y,v_z\n0,0,0,0\n1,0,0,0\n", "x", limits).rows().size(), 2u);
}

TEST(ReplayParse, InvalidLimitsAreAProgrammingError) {
  ReplayLimits limits;
  limits.max_speed_m_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(Replay::parse("t,v_x,v_y,v_z\n0,0,0,0\n", "x", limits), std::invalid_argument);
  limits.max_speed_m_s = -1.0;
  EXPECT_THROW(Replay::parse("t,v_x,v_y,v_z\n0,0,0,0\n", "x", limits), std::invalid_argument);
}

// ---- rejected input: one test per rule ----------------------------------------------------------

TEST(ReplayReject, MissingHeader) {
  expect_rejected("", 1, "", "missing header");
  expect_rejected("# only a comment\n\n# another\n", 3, "", "missing header");
}

TEST(ReplayReject, IncorrectHeader) {
  expect_rejected("# c\nt,vx,v_y,v_z\n0,0,0,0\n", 2, "", "expected the header 't,v_x,v_y,v_z'");
  expect_rejected("0,0,0,0\n1,0,0,0\n", 1, "", "got '0,0,0,0'");
  expect_rejected("t,v_x,v_y\n", 1, "", "expected the header");
  expect_rejected("t,v_x,v_y,v_z,extra\n", 1, "", "expected the header");
  expect_rejected("T,V_X,V_Y,V_Z\n", 1, "", "expected the header");
  expect_rejected("t;v_x;v_y;v_z\n", 1, "", "expected the header");
}

TEST(ReplayReject, WrongNumberOfFields) {
  expect_rejected("t,v_x,v_y,v_z\n0,0,0,0\n1,0,0\n", 3, "", "expected 4 fields");
  expect_rejected("t,v_x,v_y,v_z\n0,0,0,0,0\n", 2, "", "got 5");
  expect_rejected("t,v_x,v_y,v_z\n0,0,0,0,\n", 2, "", "got 5");
  expect_rejected("t,v_x,v_y,v_z\n0 0 0 0\n", 2, "", "got 1");
}

TEST(ReplayReject, NotANumber) {
  const std::string h = "t,v_x,v_y,v_z\n";
  expect_rejected(h + "0,0,0.1x,0\n", 2, "v_y", "not a number: '0.1x'");
  expect_rejected(h + "abc,0,0,0\n", 2, "t", "not a number: 'abc'");
  expect_rejected(h + "0,1 2,0,0\n", 2, "v_x", "not a number: '1 2'");
  expect_rejected(h + "0,0,0,0x1\n", 2, "v_z", "not a number: '0x1'");
  expect_rejected(h + "0,0,0,1,5\n", 2, "", "expected 4 fields");  // decimal comma
  expect_rejected(h + "0,+1,0,0\n", 2, "v_x", "not a number: '+1'");
  expect_rejected(h + "0,,0,0\n", 2, "v_x", "missing value");
  expect_rejected(h + "0,0,0,1e400\n", 2, "v_z", "number out of range: '1e400'");
  // Unprintable bytes are escaped in the message.
  expect_rejected(h + "0,0,0,1\r2\n", 2, "v_z", "not a number: '1\\x0d2'");
}

TEST(ReplayReject, NanOrInfinite) {
  const std::string h = "t,v_x,v_y,v_z\n";
  expect_rejected(h + "0,nan,0,0\n", 2, "v_x", "not a finite number: 'nan'");
  expect_rejected(h + "0,0,-inf,0\n", 2, "v_y", "not a finite number: '-inf'");
  expect_rejected(h + "0,0,0,0\ninfinity,0,0,0\n", 3, "t", "not a finite number: 'infinity'");
}

TEST(ReplayReject, NegativeTime) {
  expect_rejected("t,v_x,v_y,v_z\n-0.5,0,0,0\n", 2, "t", "negative time: '-0.5'");
}

// A run is as long as its file: a two-row file ending at 1e7 s would run for months and fill the
// disk with its log; the time column ends at one day (shared by every CSV format).
TEST(ReplayReject, TimeBeyondOneDay) {
  expect_rejected("t,v_x,v_y,v_z\n0,0.1,0,0\n1e7,0,0,0\n", 3, "t",
                  "time 1e+07 s is beyond the longest run a file may describe, 86400 s (24 h)");
  expect_rejected("t,v_x,v_y,v_z\n0,0.1,0,0\n1e9,0,0,0\n", 3, "t", "beyond the longest run");
  EXPECT_NO_THROW(input::Replay::parse("t,v_x,v_y,v_z\n0,0.1,0,0\n86400,0,0,0\n", "day.csv"));
}

TEST(ReplayReject, TimeNotStrictlyIncreasing) {
  expect_rejected("t,v_x,v_y,v_z\n0,0,0,0\n# c\n1,0,0,0\n1,0,0,0\n", 5, "t",
                  "time not strictly increasing: 1 s follows 1 s (line 4)");
  expect_rejected("t,v_x,v_y,v_z\n0,0,0,0\n2,0,0,0\n1.5,0,0,0\n", 4, "t",
                  "1.5 s follows 2 s (line 3)");
}

TEST(ReplayReject, NoDataRows) {
  expect_rejected("t,v_x,v_y,v_z\n", 1, "", "no data rows");
  expect_rejected("# c\nt,v_x,v_y,v_z\n\n# end\n", 4, "", "no data rows");
}

TEST(ReplayReject, SpeedAboveLimit) {
  const std::string h = "t,v_x,v_y,v_z\n";
  expect_rejected(h + "0,5.01,0,0\n", 2, "v_x", "magnitude of 5.01 m/s exceeds the limit of 5 m/s");
  expect_rejected(h + "0,0,-6,0\n", 2, "v_y", "magnitude of -6 m/s");
  ReplayLimits limits;
  limits.max_speed_m_s = 0.5;
  expect_rejected(h + "0,0,0,0\n1,0,0,0.75\n", 3, "v_z", "exceeds the limit of 0.5 m/s", limits);
}

TEST(ReplayReject, TooManyRows) {
  ReplayLimits limits;
  limits.max_rows = 2;
  expect_rejected("t,v_x,v_y,v_z\n0,0,0,0\n1,0,0,0\n# c\n2,0,0,0\n", 5, "",
                  "too many data rows (limit 2 rows)", limits);
}

TEST(ReplayReject, ErrorMessageFormat) {
  EXPECT_STREQ(parse_error("t,v_x,v_y,v_z\n0,0,0.1x,0\n").what(),
               "bad_replay.csv:2: field 'v_y': not a number: '0.1x'");
  EXPECT_STREQ(parse_error("t,v_x,v_y,v_z\n0,0,0\n").what(),
               "bad_replay.csv:2: expected 4 fields (t,v_x,v_y,v_z), got 3");
}

// ---- files -------------------------------------------------------------------------------------

TEST(ReplayFile, LoadsATemporaryFile) {
  const TempFile file("t,v_x,v_y,v_z\r\n0,0.2,0,0\r\n1,0,0,0\r\n");
  const Replay r = Replay::load_file(file.path());
  ASSERT_EQ(r.rows().size(), 2u);
  expect_vec(r.rows()[0].v_m_s, 0.2, 0.0, 0.0);
  EXPECT_EQ(r.source_name(), file.path().string());
}

TEST(ReplayFile, ErrorsInAFileNameTheFile) {
  const TempFile file("t,v_x,v_y,v_z\n0,0,0,0\n1,0,9,0\n");
  try {
    Replay::load_file(file.path());
    FAIL() << "accepted";
  } catch (const FileError& e) {
    EXPECT_EQ(e.file(), file.path().string());
    EXPECT_EQ(e.line(), 3u);
    EXPECT_EQ(e.field(), "v_y");
    EXPECT_EQ(std::string(e.what()).rfind(file.path().string() + ":3: field 'v_y': ", 0), 0u)
        << e.what();
  }
}

TEST(ReplayFile, MissingFileIsLineZero) {
  const fs::path missing = fs::temp_directory_path() / "craneassist_no_such_replay.csv";
  try {
    Replay::load_file(missing);
    FAIL() << "accepted";
  } catch (const FileError& e) {
    EXPECT_EQ(e.line(), 0u);
    EXPECT_EQ(e.field(), "");
    EXPECT_EQ(std::string(e.what()), missing.string() + ": file not found");
  }
}

TEST(ReplayFile, DirectoryIsRejected) {
  try {
    Replay::load_file(fs::temp_directory_path());
    FAIL() << "accepted";
  } catch (const FileError& e) {
    EXPECT_EQ(e.line(), 0u);
    EXPECT_NE(e.reason().find("directory"), std::string::npos) << e.what();
  }
}

// The example in docs/replay-format.md must stay valid.
TEST(ReplayFile, DocumentationExampleParses) {
  std::ifstream doc(fs::path(CRANEASSIST_SOURCE_DIR) / "docs" / "replay-format.md");
  ASSERT_TRUE(doc) << "docs/replay-format.md missing";
  std::string line;
  std::string example;
  bool in_block = false;
  while (std::getline(doc, line)) {
    if (!in_block && line == "```csv") {
      in_block = true;
    } else if (in_block && line == "```") {
      break;
    } else if (in_block) {
      example += line + "\n";
    }
  }
  ASSERT_FALSE(example.empty()) << "no ```csv block in docs/replay-format.md";
  const Replay r = Replay::parse(example, "docs example");
  EXPECT_GE(r.rows().size(), 2u);
  expect_vec(r.rows().back().v_m_s, 0.0, 0.0, 0.0);  // ends with a zero row
}

// ---- zero-order hold
// -----------------------------------------------------------------------------

Replay three_rows() {
  return Replay::parse("t,v_x,v_y,v_z\n1,0.1,0,0\n2,0,0.2,0\n4,0,0,0.3\n", "zoh.csv");
}

TEST(ReplayZeroOrderHold, ZeroOrderHold) {
  const Replay r = three_rows();
  ReplayCursor c(r);
  expect_vec(c.command_at(0.0), 0, 0, 0);  // before the first row: zero
  expect_vec(c.command_at(std::nextafter(1.0, 0.0)), 0, 0, 0);
  expect_vec(c.command_at(1.0), 0.1, 0, 0);  // a row applies from exactly its time
  expect_vec(c.command_at(1.999), 0.1, 0, 0);
  expect_vec(c.command_at(2.0), 0, 0.2, 0);
  expect_vec(c.command_at(std::nextafter(4.0, 0.0)), 0, 0.2, 0);
  expect_vec(c.command_at(4.0), 0, 0, 0.3);
  expect_vec(c.command_at(1e9), 0, 0, 0.3);  // after the last row: held
  expect_vec(c.command_at(std::numeric_limits<double>::infinity()), 0, 0, 0.3);
}

TEST(ReplayZeroOrderHold, BackwardAndJumps) {
  const Replay r = three_rows();
  ReplayCursor c(r);
  expect_vec(c.command_at(10.0), 0, 0, 0.3);  // jump to the end first
  expect_vec(c.command_at(2.5), 0, 0.2, 0);   // back
  expect_vec(c.command_at(1.0), 0.1, 0, 0);   // back onto a row time
  expect_vec(c.command_at(-1.0), 0, 0, 0);    // back before the start
  expect_vec(c.command_at(-std::numeric_limits<double>::infinity()), 0, 0, 0);
  expect_vec(c.command_at(4.0), 0, 0, 0.3);                                     // forward again
  expect_vec(c.command_at(std::numeric_limits<double>::quiet_NaN()), 0, 0, 0);  // NaN: safe zero
  expect_vec(c.command_at(4.0), 0, 0, 0.3);
}

TEST(ReplayZeroOrderHold, MatchesLinearScanForRandomQueries) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> gap(0.001, 0.1);
  std::uniform_real_distribution<double> speed(-1.0, 1.0);
  std::vector<ReplayRow> rows;
  double t = 0.5;
  for (int i = 0; i < 2000; ++i) {
    rows.push_back({t, Eigen::Vector3d(speed(rng), speed(rng), speed(rng))});
    t += gap(rng);
  }
  std::ostringstream text;
  write_replay(text, rows);
  const Replay r = Replay::parse(text.str(), "random.csv");
  const auto reference = [&](double q) -> Eigen::Vector3d {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (const ReplayRow& row : rows) {
      if (row.t_s <= q) v = row.v_m_s;
    }
    return v;
  };

  ReplayCursor c(r);
  for (const double q : cursor_queries(rows, t, rng)) {
    ASSERT_EQ(c.command_at(q), reference(q)) << "query " << q;
  }
}

TEST(ReplayZeroOrderHold, NoAllocationAndNoexcept) {
  static_assert(noexcept(std::declval<ReplayCursor&>().command_at(0.0)));
  const Replay r = three_rows();
  ReplayCursor c(r);
  double sum = 0.0;
  const std::size_t before = static_cast<std::size_t>(craneassist::test::heap_allocations());
  for (int i = 0; i < 10000; ++i) sum += c.command_at(i * 0.001).sum();
  for (int i = 10000; i > 0; --i) sum += c.command_at(i * 0.001).sum();
  EXPECT_EQ(static_cast<std::size_t>(craneassist::test::heap_allocations()), before);
  EXPECT_GT(sum, 0.0);
  // The counter does see allocations.
  std::ostringstream os;
  os << std::string(1000, 'x');
  EXPECT_GT(static_cast<std::size_t>(craneassist::test::heap_allocations()), before);
}

// ---- writer ------------------------------------------------------------------------------------

TEST(ReplayWrite, Format) {
  std::ostringstream out;
  write_replay(out, {{0.0, Eigen::Vector3d(0.1, -0.25, 0.0)}, {1.5, Eigen::Vector3d::Zero()}});
  EXPECT_EQ(out.str(), "t,v_x,v_y,v_z\n0,0.1,-0.25,0\n1.5,0,0,0\n");
}

TEST(ReplayWrite, RoundTripIsBitExact) {
  // Awkward values, then random bit patterns within the limits (incl. subnormals).
  std::vector<ReplayRow> rows = {
      {0.0, Eigen::Vector3d(0.1, 1.0 / 3.0, -2.0 / 3.0)},
      {0.1, Eigen::Vector3d(std::numeric_limits<double>::min(), -0.0, 5.0)},
      {1e-300, Eigen::Vector3d(std::numeric_limits<double>::denorm_min(), -5.0, 4.999999999999999)},
      {12345.678901234567, Eigen::Vector3d(1e-17, -1.2345678901234567, 0.30000000000000004)},
  };
  std::sort(rows.begin(), rows.end(),
            [](const ReplayRow& a, const ReplayRow& b) { return a.t_s < b.t_s; });
  std::mt19937_64 rng(7);
  const auto random_speed = [&] {
    while (true) {
      const double v = std::bit_cast<double>(rng());
      if (std::isfinite(v) && std::abs(v) <= 5.0) return v;
    }
  };
  double t = rows.back().t_s;
  for (int i = 0; i < 5000; ++i) {
    t = std::nextafter(t, 1e300) + std::abs(random_speed()) * 1e3;
    rows.push_back({t, Eigen::Vector3d(random_speed(), random_speed(), random_speed())});
  }

  std::ostringstream out;
  write_replay(out, rows);
  const Replay r = Replay::parse(out.str(), "roundtrip.csv");
  ASSERT_EQ(r.rows().size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(r.rows()[i].t_s),
              std::bit_cast<std::uint64_t>(rows[i].t_s))
        << "row " << i;
    for (Eigen::Index k = 0; k < 3; ++k) {
      EXPECT_EQ(std::bit_cast<std::uint64_t>(r.rows()[i].v_m_s[k]),
                std::bit_cast<std::uint64_t>(rows[i].v_m_s[k]))
          << "row " << i << " component " << k << " value " << rows[i].v_m_s[k];
    }
  }
}

// ---- the stop column ---------------------------------------------------------------------------

TEST(ReplayStopColumn, StopRowsGiveANonFiniteCommandAndOthersTheirVelocity) {
  const Replay r = Replay::parse(
      "t,v_x,v_y,v_z,stop\n0,0.3,0,0,0\n1,0,0,0,1\n1.5, 0, -0, 0 , 0\n2,0,0.2,0,0\n", "stop.csv");
  ASSERT_EQ(r.rows().size(), 4u);
  EXPECT_FALSE(r.rows()[0].stop);
  EXPECT_TRUE(r.rows()[1].stop);
  EXPECT_FALSE(r.rows()[2].stop);
  ReplayCursor c(r);
  expect_vec(c.command_at(0.5), 0.3, 0, 0);
  const Eigen::Vector3d stop = c.command_at(1.0);
  EXPECT_TRUE(std::isnan(stop.x()) && std::isnan(stop.y()) && std::isnan(stop.z()));
  EXPECT_TRUE(c.command_at(1.49).hasNaN());
  expect_vec(c.command_at(1.5), 0, 0, 0);
  expect_vec(c.command_at(3.0), 0, 0.2, 0);
  EXPECT_TRUE(c.command_at(1.2).hasNaN());  // going back
  // A replay ending in a stop row holds the stop.
  const Replay end = Replay::parse("t,v_x,v_y,v_z,stop\n0,0.1,0,0,0\n1,0,0,0,1\n", "end.csv");
  ReplayCursor e(end);
  EXPECT_TRUE(e.command_at(100.0).hasNaN());
}

TEST(ReplayStopColumn, StrictErrorsNameTheStopField) {
  const std::string h = "t,v_x,v_y,v_z,stop\n";
  expect_rejected(h + "0,0,0,0,2\n", 2, "stop", "expected 0 or 1, got '2'");
  expect_rejected(h + "0,0,0,0,yes\n", 2, "stop", "expected 0 or 1, got 'yes'");
  expect_rejected(h + "0,0,0,0,1.0\n", 2, "stop", "expected 0 or 1, got '1.0'");
  expect_rejected(h + "0,0,0,0,\n", 2, "stop", "missing value");
  expect_rejected(h + "0,0,0,0\n", 2, "", "expected 5 fields (t,v_x,v_y,v_z,stop), got 4");
  expect_rejected(h + "0,0,0,0,0,1\n", 2, "", "expected 5 fields");
  expect_rejected(h + "0,0,0.1,0,1\n", 2, "v_y", "must be 0 in a stop row (stop = 1), got '0.1'");
  expect_rejected("t,v_x,v_y,v_z,Stop\n", 1, "",
                  "expected the header 't,v_x,v_y,v_z', then any of the columns 'stop', 'wait' "
                  "and 'load_kg' in this order (at most 't,v_x,v_y,v_z,stop,wait,load_kg'), got "
                  "'t,v_x,v_y,v_z,Stop'");
  expect_rejected("t,v_x,v_y,v_z\n0,0,0,0,1\n", 2, "", "expected 4 fields (t,v_x,v_y,v_z), got 5");
  const FileError e = parse_error(h + "0,0,0,0,0\n1,0,0,0,x\n");
  EXPECT_EQ(std::string(e.what()), "bad_replay.csv:3: field 'stop': expected 0 or 1, got 'x'");
}

TEST(ReplayStopColumn, WrittenOnlyWhenARowStopsAndRoundTrips) {
  std::vector<ReplayRow> rows = {{0.0, Eigen::Vector3d(0.1, 0, 0)},
                                 {0.5, Eigen::Vector3d::Zero(), true},
                                 {1.25, Eigen::Vector3d(0, 0.2, -0.1)}};
  std::ostringstream out;
  write_replay(out, rows);
  EXPECT_EQ(out.str(), "t,v_x,v_y,v_z,stop\n0,0.1,0,0,0\n0.5,0,0,0,1\n1.25,0,0.2,-0.1,0\n");
  const Replay r = Replay::parse(out.str(), "rt.csv");
  ASSERT_EQ(r.rows().size(), 3u);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(r.rows()[i].t_s, rows[i].t_s);
    EXPECT_EQ(r.rows()[i].v_m_s, rows[i].v_m_s);
    EXPECT_EQ(r.rows()[i].stop, rows[i].stop);
  }
  // Without a stop row: the 4-column form, and an old file round-trips byte for byte.
  const std::string old = "t,v_x,v_y,v_z\n0,0.1,-0.25,0\n1.5,0,0,0\n";
  std::ostringstream again;
  write_replay(again, Replay::parse(old, "old.csv").rows());
  EXPECT_EQ(again.str(), old);
}

TEST(ReplayStopColumn, ShippedDropoutReplayHasStopRows) {
  const Replay r = Replay::load_file(fs::path(CRANEASSIST_SOURCE_DIR) / "examples" / "replays" /
                                     "input_dropout.csv");
  int stops = 0;
  for (const ReplayRow& row : r.rows()) stops += row.stop;
  EXPECT_GE(stops, 1);
}

// ---- the load_kg column ------------------------------------------------------------------------

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Checks a load: the same bits, or both NaN.
void expect_load(double actual, double expected) {
  if (std::isnan(expected)) {
    EXPECT_TRUE(std::isnan(actual)) << actual;
  } else {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(actual), std::bit_cast<std::uint64_t>(expected))
        << actual << " != " << expected;
  }
}

TEST(ReplayLoadColumn, HeaderForms) {
  const Replay plain = Replay::parse("t,v_x,v_y,v_z\n0,0,0,0\n", "h.csv");
  EXPECT_FALSE(plain.has_load());
  expect_load(plain.rows()[0].load_kg, kNaN);
  const Replay stop = Replay::parse("t,v_x,v_y,v_z,stop\n0,0,0,0,1\n", "h.csv");
  EXPECT_FALSE(stop.has_load());
  EXPECT_TRUE(stop.rows()[0].stop);
  const Replay load = Replay::parse("t,v_x,v_y,v_z,load_kg\n0,0.1,0,0,450\n", "h.csv");
  EXPECT_TRUE(load.has_load());
  EXPECT_FALSE(load.rows()[0].stop);
  expect_vec(load.rows()[0].v_m_s, 0.1, 0, 0);
  expect_load(load.rows()[0].load_kg, 450.0);
  const Replay both =
      Replay::parse("t,v_x,v_y,v_z,stop,load_kg\n0,0.1,0,0,0,12.5\n1,0,0,0,1,0\n", "h.csv");
  EXPECT_TRUE(both.has_load());
  EXPECT_FALSE(both.rows()[0].stop);
  expect_load(both.rows()[0].load_kg, 12.5);
  EXPECT_TRUE(both.rows()[1].stop);  // a stop row may set a load
  expect_load(both.rows()[1].load_kg, 0.0);
  // The header rules of the other columns: comments first, spaces and tabs around names, CRLF, BOM.
  const Replay spaced = Replay::parse(
      "\xEF\xBB\xBF# c\r\n\r\n t ,v_x,\tv_y, v_z , stop ,\tload_kg \r\n0,0,0,0,0,7\r\n", "h.csv");
  expect_load(spaced.rows()[0].load_kg, 7.0);
}

TEST(ReplayLoadColumn, OtherHeadersNameTheOptionalColumnsAndTheirOrder) {
  const std::string expected =
      "expected the header 't,v_x,v_y,v_z', then any of the columns 'stop', 'wait' and 'load_kg' "
      "in this order (at most 't,v_x,v_y,v_z,stop,wait,load_kg'), got ";
  expect_rejected("# c\nt,v_x,v_y,v_z,load_kg,stop\n0,0,0,0,0,0\n", 2, "",
                  expected + "'t,v_x,v_y,v_z,load_kg,stop'");
  expect_rejected("t,v_x,v_y,v_z,Load_kg\n0,0,0,0,0\n", 1, "",
                  expected + "'t,v_x,v_y,v_z,Load_kg'");
  expect_rejected("t,v_x,v_y,v_z,load\n", 1, "", expected + "'t,v_x,v_y,v_z,load'");
  expect_rejected("t,v_x,v_y,v_z,stop,load_kg,x\n", 1, "", expected);
  expect_rejected("t,v_x,v_y,v_z,load_kg,load_kg\n", 1, "", expected);
  expect_rejected("t,v_x,v_y,load_kg\n", 1, "", expected);
  expect_rejected("\n\n# c\nt,v_x,v_y,v_z;load_kg\n", 4, "", expected);
  EXPECT_STREQ(parse_error("t,v_x,v_y,v_z,LOAD_KG\n0,0,0,0,1\n").what(),
               ("bad_replay.csv:1: " + expected + "'t,v_x,v_y,v_z,LOAD_KG'").c_str());
  // Without a header the message is unchanged.
  expect_rejected("# c\n", 1, "",
                  "missing header 't,v_x,v_y,v_z' (no line other than comments and blank lines)");
}

TEST(ReplayLoadColumn, EmptyCellsLeaveTheLoadUnset) {
  const Replay r = Replay::parse(
      "t,v_x,v_y,v_z,load_kg\n"
      "0,0,0,0,\n"
      "# grab\n"
      "1,0.1,0,0,450\n"
      "2,0,0,0, \n"
      "3,0,0,0,\t\r\n"
      "\n"
      "4,0,0,0,0\n"
      "5 , 0 , 0 , 0 ,",  // no final newline
      "e.csv");
  ASSERT_EQ(r.rows().size(), 6u);
  const double expected[] = {kNaN, 450.0, kNaN, kNaN, 0.0, kNaN};
  for (std::size_t i = 0; i < r.rows().size(); ++i) {
    SCOPED_TRACE(i);
    expect_load(r.rows()[i].load_kg, expected[i]);
  }
  expect_vec(r.rows()[1].v_m_s, 0.1, 0, 0);
  EXPECT_EQ(r.end_time_s(), 5.0);
  EXPECT_TRUE(r.has_load());
  // With the stop column too.
  const Replay s =
      Replay::parse("t,v_x,v_y,v_z,stop,load_kg\n0,0,0,0,0,\n1,0,0,0,1,\n2,0,0,0,0,3\n", "s.csv");
  expect_load(s.rows()[0].load_kg, kNaN);
  EXPECT_TRUE(s.rows()[1].stop);
  expect_load(s.rows()[1].load_kg, kNaN);
  expect_load(s.rows()[2].load_kg, 3.0);
  // A column with no number in it sets no load.
  EXPECT_FALSE(Replay::parse("t,v_x,v_y,v_z,load_kg\n0,0,0,0,\n1,0,0,0,\n", "x").has_load());
}

TEST(ReplayLoadColumn, RangeIsZeroToOneHundredTonnes) {
  const Replay r = Replay::parse(
      "t,v_x,v_y,v_z,load_kg\n0,0,0,0,0\n1,0,0,0,100000\n2,0,0,0,-0\n3,0,0,0,1e5\n4,0,0,0,4.9e-"
      "324\n",
      "range.csv");
  expect_load(r.rows()[0].load_kg, 0.0);
  expect_load(r.rows()[1].load_kg, Replay::kMaxLoad_kg);
  expect_load(r.rows()[2].load_kg, -0.0);  // negative zero is no negative load
  expect_load(r.rows()[3].load_kg, 100000.0);
  expect_load(r.rows()[4].load_kg, std::numeric_limits<double>::denorm_min());
}

TEST(ReplayLoadColumn, StrictErrorsNameTheLoadField) {
  const std::string h = "t,v_x,v_y,v_z,load_kg\n";
  const std::string range = "must be between 0 and 100000 kg, got ";
  expect_rejected(h + "0,0,0,0,-1\n", 2, "load_kg", range + "'-1'");
  expect_rejected(h + "0,0,0,0,-1e-300\n", 2, "load_kg", range + "'-1e-300'");
  expect_rejected(h + "0,0,0,0,100000.00000000001\n", 2, "load_kg", range + "'100000.00000000001'");
  expect_rejected(h + "0,0,0,0,2e5\n", 2, "load_kg", range + "'2e5'");
  expect_rejected(h + "0,0,0,0,1e308\n", 2, "load_kg", range + "'1e308'");
  expect_rejected(h + "0,0,0,0,nan\n", 2, "load_kg", "not a finite number: 'nan'");
  expect_rejected(h + "0,0,0,0,NaN\n", 2, "load_kg", "not a finite number: 'NaN'");
  expect_rejected(h + "0,0,0,0,inf\n", 2, "load_kg", "not a finite number: 'inf'");
  expect_rejected(h + "0,0,0,0,-infinity\n", 2, "load_kg", "not a finite number: '-infinity'");
  expect_rejected(h + "0,0,0,0,1e400\n", 2, "load_kg", "number out of range: '1e400'");
  expect_rejected(h + "0,0,0,0,heavy\n", 2, "load_kg", "not a number: 'heavy'");
  expect_rejected(h + "0,0,0,0,450 kg\n", 2, "load_kg", "not a number: '450 kg'");
  expect_rejected(h + "0,0,0,0,+450\n", 2, "load_kg", "not a number: '+450'");
  expect_rejected(h + "0,0,0,0,0x10\n", 2, "load_kg", "not a number: '0x10'");
  expect_rejected(h + "0,0,0,0,1\r\r\n", 2, "load_kg", "not a number: '1\\x0d'");
  expect_rejected(h + "0,0,0,0,\r\r\n", 2, "load_kg", "not a number: '\\x0d'");
  // Field counts: a final empty cell is a field; one too many is not filled in.
  expect_rejected(h + "0,0,0,0\n", 2, "", "expected 5 fields (t,v_x,v_y,v_z,load_kg), got 4");
  expect_rejected(h + "0,0,0,0,,\n", 2, "", "expected 5 fields (t,v_x,v_y,v_z,load_kg), got 6");
  expect_rejected(h + "0,0,0,0,1,\n", 2, "", "got 6");
  expect_rejected(h + ",,,,\n", 2, "t", "missing value");
  // The other columns' errors come first, as in every row.
  expect_rejected(h + "0,0,0,0,\n1,0.1x,0,0,\n", 3, "v_x", "not a number: '0.1x'");
  expect_rejected(h + "0,0,0,0,\n0,0,0,0,\n", 3, "t", "time not strictly increasing");
  // With the stop column: each column its own errors.
  const std::string hs = "t,v_x,v_y,v_z,stop,load_kg\n";
  expect_rejected(hs + "0,0,0,0,,5\n", 2, "stop", "missing value");
  expect_rejected(hs + "0,0,0,0,1,-5\n", 2, "load_kg", range + "'-5'");
  expect_rejected(hs + "0,0.1,0,0,1,\n", 2, "v_x", "must be 0 in a stop row");
  expect_rejected(hs + "0,0,0,0,0\n", 2, "",
                  "expected 6 fields (t,v_x,v_y,v_z,stop,load_kg), got 5");
  // The line counts comments, blank lines and rows with an empty cell.
  const FileError e = parse_error("# c\n" + h + "0,0,0,0,\n\n1,0,0,0,450\n2,0,0,0,\n3,0,0,0,-5\n");
  EXPECT_EQ(std::string(e.what()),
            "bad_replay.csv:7: field 'load_kg': must be between 0 and 100000 kg, got '-5'");
  const FileError crlf =
      parse_error("\xEF\xBB\xBFt,v_x,v_y,v_z,load_kg\r\n0,0,0,0,\r\n1,0,0,0,x\r\n");
  EXPECT_EQ(std::string(crlf.what()), "bad_replay.csv:3: field 'load_kg': not a number: 'x'");
}

// Loads: row 1 none, 2 sets 0, 3 sets 450, 5 keeps it, 6 sets 0, 8 keeps it.
Replay load_rows() {
  return Replay::parse(
      "t,v_x,v_y,v_z,stop,load_kg\n"
      "1,0.1,0,0,0,\n"
      "2,0,0.2,0,0,0\n"
      "3,0,0,0,0,450\n"
      "5,0,0,0,1,\n"
      "6,0,0,0,0,0\n"
      "8,0,0,0.3,0,\n",
      "load.csv");
}

TEST(ReplayLoadColumn, CursorHoldsTheLastLoadSet) {
  const Replay r = load_rows();
  ReplayCursor c(r);
  expect_load(c.load_at(0.0), kNaN);  // before the first row
  expect_load(c.load_at(1.0), kNaN);  // a row with an empty cell: no load yet
  expect_load(c.load_at(std::nextafter(2.0, 0.0)), kNaN);
  expect_load(c.load_at(2.0), 0.0);  // a row applies from exactly its time
  expect_load(c.load_at(2.999), 0.0);
  expect_load(c.load_at(3.0), 450.0);
  expect_load(c.load_at(4.0), 450.0);
  expect_load(c.load_at(5.0), 450.0);  // an empty cell keeps it (in a stop row too)
  expect_load(c.load_at(5.999), 450.0);
  expect_load(c.load_at(6.0), 0.0);
  expect_load(c.load_at(8.0), 0.0);
  expect_load(c.load_at(1e9), 0.0);  // after the last row: held
  expect_load(c.load_at(std::numeric_limits<double>::infinity()), 0.0);
  expect_load(c.load_at(kNaN), kNaN);  // NaN query
  // Going back and jumping.
  expect_load(c.load_at(5.5), 450.0);
  expect_load(c.load_at(1.5), kNaN);
  expect_load(c.load_at(-1.0), kNaN);
  expect_load(c.load_at(-std::numeric_limits<double>::infinity()), kNaN);
  expect_load(c.load_at(7.0), 0.0);
  expect_load(c.load_at(3.0), 450.0);
}

TEST(ReplayLoadColumn, CursorWithoutLoadsGivesNaN) {
  for (const char* text :
       {"t,v_x,v_y,v_z\n0,0.1,0,0\n1,0,0,0\n", "t,v_x,v_y,v_z,load_kg\n0,0.1,0,0,\n1,0,0,0,\n"}) {
    SCOPED_TRACE(text);
    const Replay r = Replay::parse(text, "none.csv");
    EXPECT_FALSE(r.has_load());
    ReplayCursor c(r);
    for (const double t : {-1.0, 0.0, 0.5, 1.0, 100.0}) {
      expect_load(c.load_at(t), kNaN);
      expect_vec(c.command_at(t), t >= 0.0 && t < 1.0 ? 0.1 : 0.0, 0, 0);
    }
  }
}

// command_at and load_at on one cursor, each cycle with the same time (the loop's use), or with
// times going different ways: each answers as if alone.
TEST(ReplayLoadColumn, CursorLookupsAreIndependent) {
  const Replay r = load_rows();
  ReplayCursor both(r);
  ReplayCursor commands(r);
  ReplayCursor loads(r);
  for (double t = 0.0; t < 10.0; t += 0.01) {
    const Eigen::Vector3d v = both.command_at(t);
    const double load = both.load_at(t);
    const Eigen::Vector3d v_alone = commands.command_at(t);
    EXPECT_TRUE(v == v_alone || (v.hasNaN() && v_alone.hasNaN())) << t;
    expect_load(load, loads.load_at(t));
  }
  ReplayCursor c(r);
  expect_vec(c.command_at(8.5), 0, 0, 0.3);
  expect_load(c.load_at(3.5), 450.0);  // back, for the load only
  expect_vec(c.command_at(8.5), 0, 0, 0.3);
  expect_load(c.load_at(1.0), kNaN);
  expect_vec(c.command_at(2.0), 0, 0.2, 0);
  expect_load(c.load_at(9.0), 0.0);
  EXPECT_TRUE(c.command_at(5.0).hasNaN());
}

TEST(ReplayLoadColumn, CursorMatchesLinearScanForRandomQueries) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> gap(0.001, 0.1);
  std::uniform_real_distribution<double> kg(0.0, Replay::kMaxLoad_kg);
  std::uniform_int_distribution<int> sets(0, 9);
  std::vector<ReplayRow> rows;
  double t = 0.5;
  for (int i = 0; i < 2000; ++i) {
    rows.push_back({t, Eigen::Vector3d::Zero(), false, sets(rng) == 0 ? kg(rng) : kNaN});
    t += gap(rng);
  }
  std::ostringstream text;
  write_replay(text, rows);
  const Replay r = Replay::parse(text.str(), "random.csv");
  const auto reference = [&](double q) {
    double load = kNaN;
    for (const ReplayRow& row : rows) {
      if (row.t_s <= q && !std::isnan(row.load_kg)) load = row.load_kg;
    }
    return load;
  };
  ReplayCursor c(r);
  for (const double q : cursor_queries(rows, t, rng)) {
    const double expected = reference(q);
    const double actual = c.load_at(q);
    ASSERT_TRUE(std::bit_cast<std::uint64_t>(actual) == std::bit_cast<std::uint64_t>(expected) ||
                (std::isnan(actual) && std::isnan(expected)))
        << "query " << q << ": " << actual << " != " << expected;
  }
}

TEST(ReplayLoadColumn, CursorNoAllocationAndNoexcept) {
  static_assert(noexcept(std::declval<ReplayCursor&>().load_at(0.0)));
  const Replay r = load_rows();
  ReplayCursor c(r);
  double sum = 0.0;
  const std::size_t before = static_cast<std::size_t>(craneassist::test::heap_allocations());
  for (int i = 0; i < 10000; ++i) {
    const double load = c.load_at(i * 0.001);
    if (!std::isnan(load)) sum += load;
  }
  for (int i = 10000; i > 0; --i) {
    const double load = c.load_at(i * 0.001);
    if (!std::isnan(load)) sum += load;
  }
  EXPECT_EQ(static_cast<std::size_t>(craneassist::test::heap_allocations()), before);
  EXPECT_GT(sum, 0.0);
}

TEST(ReplayLoadColumn, WrittenOnlyWhenARowSetsALoad) {
  std::ostringstream load;
  write_replay(load, {{0.0, Eigen::Vector3d(0.1, 0, 0), false, 0.0},
                      {1.0, Eigen::Vector3d::Zero()},
                      {2.5, Eigen::Vector3d(0, 0.2, 0), false, 450.25}});
  EXPECT_EQ(load.str(), "t,v_x,v_y,v_z,load_kg\n0,0.1,0,0,0\n1,0,0,0,\n2.5,0,0.2,0,450.25\n");
  std::ostringstream both;
  write_replay(both,
               {{0.0, Eigen::Vector3d::Zero(), true}, {1.0, Eigen::Vector3d::Zero(), false, 7.0}});
  EXPECT_EQ(both.str(), "t,v_x,v_y,v_z,stop,load_kg\n0,0,0,0,1,\n1,0,0,0,0,7\n");
  std::ostringstream none;
  write_replay(none, {{0.0, Eigen::Vector3d::Zero(), false, kNaN}, {1.0, Eigen::Vector3d::Zero()}});
  EXPECT_EQ(none.str(), "t,v_x,v_y,v_z\n0,0,0,0\n1,0,0,0\n");
  // A file in the written form round-trips byte for byte.
  for (const std::string& text : {load.str(), both.str(), none.str()}) {
    std::ostringstream again;
    write_replay(again, Replay::parse(text, "rt.csv").rows());
    EXPECT_EQ(again.str(), text);
  }
}

TEST(ReplayLoadColumn, RoundTripIsBitExact) {
  std::mt19937_64 rng(3);
  const auto random_load = [&] {
    while (true) {
      const double kg = std::bit_cast<double>(rng());
      if (kg >= 0.0 && kg <= Replay::kMaxLoad_kg) return kg;  // incl. subnormals
    }
  };
  std::vector<ReplayRow> rows = {
      {0.0, Eigen::Vector3d::Zero(), false, kNaN},
      {0.5, Eigen::Vector3d::Zero(), true, -0.0},
      {1.0, Eigen::Vector3d(0.1, 0, 0), false, Replay::kMaxLoad_kg},
      {1.5, Eigen::Vector3d::Zero(), false, 1.0 / 3.0},
      {2.0, Eigen::Vector3d::Zero(), false, std::numeric_limits<double>::denorm_min()},
  };
  std::uniform_int_distribution<int> sets(0, 2);
  for (int i = 0; i < 5000; ++i) {
    rows.push_back(
        {3.0 + i * 0.01, Eigen::Vector3d::Zero(), false, sets(rng) == 0 ? kNaN : random_load()});
  }
  std::ostringstream out;
  write_replay(out, rows);
  const Replay r = Replay::parse(out.str(), "roundtrip.csv");
  EXPECT_TRUE(r.has_load());
  ASSERT_EQ(r.rows().size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(r.rows()[i].stop, rows[i].stop);
    expect_load(r.rows()[i].load_kg, rows[i].load_kg);
  }
  // Without a load: no column, and none read back.
  for (ReplayRow& row : rows) row.load_kg = kNaN;
  std::ostringstream plain;
  write_replay(plain, rows);
  EXPECT_TRUE(plain.str().starts_with("t,v_x,v_y,v_z,stop\n"));
  EXPECT_FALSE(Replay::parse(plain.str(), "plain.csv").has_load());
}

// The load examples in docs/replay-format.md (the ```csv blocks with a load_kg column) parse.
TEST(ReplayLoadColumn, DocumentationExamplesParse) {
  std::ifstream doc(fs::path(CRANEASSIST_SOURCE_DIR) / "docs" / "replay-format.md");
  ASSERT_TRUE(doc) << "docs/replay-format.md missing";
  std::vector<std::string> blocks;
  std::string line;
  bool in_block = false;
  while (std::getline(doc, line)) {
    if (!in_block && line == "```csv") {
      in_block = true;
      blocks.emplace_back();
    } else if (in_block && line == "```") {
      in_block = false;
    } else if (in_block) {
      blocks.back() += line + "\n";
    }
  }
  int with_load = 0;
  for (const std::string& block : blocks) {
    SCOPED_TRACE(block);
    const Replay r = Replay::parse(block, "docs example");
    with_load += r.has_load();
    if (block.find("load_kg") != std::string::npos) {
      EXPECT_TRUE(r.has_load());
    }
  }
  EXPECT_GE(with_load, 2);
}

// The wait column (docs/replay-format.md#waits): a flag after stop and before load_kg, in every
// combination with them, strict like stop, written only when a row waits.
TEST(ReplayWaitColumn, ReadInEveryCombinationStrictAndRoundTrips) {
  const Replay w = Replay::parse("t,v_x,v_y,v_z,wait\n0,0.1,0,0,0\n1,0,0,0,1\n", "w.csv");
  ASSERT_EQ(w.rows().size(), 2u);
  EXPECT_FALSE(w.rows()[0].wait);
  EXPECT_TRUE(w.rows()[1].wait);
  EXPECT_TRUE(w.has_waits());
  const Replay all = Replay::parse(
      "t,v_x,v_y,v_z,stop,wait,load_kg\n0,0.1,0,0,0,0,\n1,0,0,0,1,0,300\n2,0,0,0,0,1,\n", "a.csv");
  ASSERT_EQ(all.rows().size(), 3u);
  EXPECT_TRUE(all.rows()[1].stop);
  EXPECT_FALSE(all.rows()[1].wait);
  EXPECT_EQ(all.rows()[1].load_kg, 300.0);
  EXPECT_TRUE(all.rows()[2].wait);
  EXPECT_TRUE(std::isnan(all.rows()[2].load_kg));
  const Replay wl = Replay::parse("t,v_x,v_y,v_z,wait,load_kg\n0,0,0,0,1,450\n", "wl.csv");
  EXPECT_TRUE(wl.rows()[0].wait);
  EXPECT_EQ(wl.rows()[0].load_kg, 450.0);
  EXPECT_FALSE(Replay::parse("t,v_x,v_y,v_z\n0,0,0,0\n", "n.csv").has_waits());

  const std::string h = "t,v_x,v_y,v_z,wait\n";
  expect_rejected(h + "0,0,0,0,2\n", 2, "wait", "expected 0 or 1, got '2'");
  expect_rejected(h + "0,0,0,0,\n", 2, "wait", "missing value");
  expect_rejected(h + "0,0,0,0\n", 2, "", "expected 5 fields (t,v_x,v_y,v_z,wait), got 4");
  expect_rejected("t,v_x,v_y,v_z,wait,stop\n", 1, "", "then any of the columns 'stop', 'wait'");

  std::vector<ReplayRow> rows = {{0.0, Eigen::Vector3d(0.1, 0, 0)},
                                 {0.5, Eigen::Vector3d::Zero(), false, NAN, true},
                                 {1.25, Eigen::Vector3d::Zero(), true, 200.0, true}};
  std::ostringstream out;
  write_replay(out, rows);
  EXPECT_EQ(
      out.str(),
      "t,v_x,v_y,v_z,stop,wait,load_kg\n0,0.1,0,0,0,0,\n0.5,0,0,0,0,1,\n1.25,0,0,0,1,1,200\n");
  const Replay back = Replay::parse(out.str(), "rt.csv");
  ASSERT_EQ(back.rows().size(), 3u);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(back.rows()[i].wait, rows[i].wait) << i;
    EXPECT_EQ(back.rows()[i].stop, rows[i].stop) << i;
  }
}

}  // namespace
}  // namespace craneassist::input
