// The one CSV reader behind the three input file formats (replays, prescribed paths, joint
// trajectories): each rule gives the same FileError, naming file, line and field in one message
// style, in every format. The formats' own rules are in test_replay.cpp,
// test_prescribed_path.cpp and test_joint_trajectory.cpp.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "craneassist/files/text_file.hpp"
#include "craneassist/input/file_error.hpp"
#include "craneassist/input/joint_trajectory.hpp"
#include "craneassist/input/prescribed_path.hpp"
#include "craneassist/input/replay.hpp"
#include "file_error_checks.hpp"
#include "thrown_error.hpp"

namespace craneassist::input {
namespace {

namespace fs = std::filesystem;

constexpr const char* kSource = "data.csv";

struct Format {
  std::string name;
  std::vector<std::string> columns;
  // When the header is not the format's: the headers it expects (as the message lists them) and
  // the shortest of them.
  std::string expected_headers;
  std::string shortest_header;
  std::size_t max_rows;
  std::function<void(std::string_view text)> parse;
  std::function<void(const fs::path& file)> load;

  std::string header() const {
    std::string h;
    for (const auto& c : columns) h += (h.empty() ? "" : ",") + c;
    return h;
  }
};

std::vector<Format> formats() {
  const std::vector<std::string> trajectory = {"t",      "q_1",     "q_2",    "qdot_1",
                                               "qdot_2", "qddot_1", "qddot_2"};
  return {
      {"replay",
       {"t", "v_x", "v_y", "v_z"},
       "'t,v_x,v_y,v_z', then any of the columns 'stop', 'wait' and 'load_kg' in this order (at "
       "most 't,v_x,v_y,v_z,stop,wait,load_kg')",
       "t,v_x,v_y,v_z",
       ReplayLimits{}.max_rows,
       [](std::string_view text) { Replay::parse(text, kSource); },
       [](const fs::path& file) { Replay::load_file(file); }},
      {"path",
       {"t", "x", "y", "z"},
       "'t,x,y,z'",
       "t,x,y,z",
       PrescribedPathLimits::kMaxViaPoints,
       [](std::string_view text) { PrescribedPath::parse(text, kSource); },
       [](const fs::path& file) { PrescribedPath::load_file(file); }},
      // The joint count comes from the header: one joint when it names none.
      {"trajectory", trajectory, "'t,q_1,qdot_1,qddot_1'", "t,q_1,qdot_1,qddot_1",
       JointTrajectory::kMaxRows,
       [](std::string_view text) { JointTrajectory::parse(text, kSource); },
       [](const fs::path& file) { JointTrajectory::load_file(file); }},
  };
}

// A data row: time t, every other field 0 except `column`, which is `text` (column 0 is t).
std::string row(const Format& format, std::string t, std::size_t column = 0,
                const std::string& text = {}) {
  std::string out = column == 0 && !text.empty() ? text : std::move(t);
  for (std::size_t i = 1; i < format.columns.size(); ++i) {
    out += ',';
    out += i == column ? text : std::string("0");
  }
  return out;
}

// The error a text gives (a failure when it is accepted).
FileError error_of(const Format& format, std::string_view text) {
  return test::thrown_error<FileError>([&] { format.parse(text); },
                                       format.name + " accepted:\n" + std::string(text));
}

// Checks file, line, field, the whole reason and the what() layout: "FILE:LINE: field 'NAME':
// REASON", or "FILE:LINE: REASON" without a field.
void expect_error(const Format& format, std::string_view text, std::size_t line,
                  const std::string& field, const std::string& reason) {
  SCOPED_TRACE(format.name + ":\n" + std::string(text));
  const FileError e = error_of(format, text);
  test::expect_file_error(e, kSource, line, field, reason);
  EXPECT_EQ(e.reason(), reason);
}

// A file: a comment, the header, valid rows at t = 0, 1, ... and then `last` if given.
std::string file_with(const Format& format, std::size_t rows, const std::string& last = {}) {
  std::string text = "# comment\n";
  text += format.header();
  text += '\n';
  for (std::size_t i = 0; i < rows; ++i) text += row(format, std::to_string(i)) + "\n";
  if (!last.empty()) text += last + "\n";
  return text;
}

TEST(InputFiles, BadHeaderIsReportedAtItsLineWithTheExpectedHeader) {
  for (const Format& f : formats()) {
    expect_error(f, "# c\n\nt,a,b\n0,0,0\n", 3, "",
                 "expected the header " + f.expected_headers + ", got 't,a,b'");
  }
}

TEST(InputFiles, MissingHeaderAndNoRows) {
  for (const Format& f : formats()) {
    const std::string reason =
        "missing header '" + f.shortest_header + "' (no line other than comments and blank lines)";
    expect_error(f, "", 1, "", reason);  // an empty file: line 1
    expect_error(f, "# only\n\n# comments\n", 3, "", reason);
    expect_error(f, "# c\n" + f.header() + "\n# end\n", 3, "", "no data rows after the header");
  }
}

TEST(InputFiles, BadNumberNamesTheFieldAndTheLine) {
  for (const Format& f : formats()) {
    // The second column of the fourth data row: file line 6, after the comment and the header.
    expect_error(f, file_with(f, 3, row(f, "3", 1, "0.1x")), 6, f.columns[1],
                 "not a number: '0.1x'");
    expect_error(f, file_with(f, 3, row(f, "3", 2, "1 m")), 6, f.columns[2], "not a number: '1 m'");
    expect_error(f, file_with(f, 1, row(f, "", 0, "x1")), 4, "t", "not a number: 'x1'");
    expect_error(f, file_with(f, 1, row(f, "1", 1, "+1")), 4, f.columns[1], "not a number: '+1'");
  }
}

TEST(InputFiles, NonFiniteOutOfRangeAndMissingValues) {
  for (const Format& f : formats()) {
    const std::size_t last = f.columns.size() - 1;
    const std::string& name = f.columns[last];
    expect_error(f, file_with(f, 1, row(f, "1", last, "nan")), 4, name,
                 "not a finite number: 'nan'");
    expect_error(f, file_with(f, 1, row(f, "1", last, "-inf")), 4, name,
                 "not a finite number: '-inf'");
    expect_error(f, file_with(f, 1, row(f, "1", last, "1e400")), 4, name,
                 "number out of range: '1e400'");
    expect_error(f, file_with(f, 1, row(f, "1", 1, "")), 4, f.columns[1], "missing value");
    expect_error(f, file_with(f, 1, row(f, "", 0, "infinity")), 4, "t",
                 "not a finite number: 'infinity'");
  }
}

TEST(InputFiles, TimeRules) {
  for (const Format& f : formats()) {
    const std::string h = f.header() + "\n";
    expect_error(f, h + row(f, "-0.5") + "\n", 2, "t", "negative time: '-0.5'");
    expect_error(f, h + row(f, "0") + "\n" + row(f, "2") + "\n# c\n" + row(f, "1.5") + "\n", 5, "t",
                 "time not strictly increasing: 1.5 s follows 2 s (line 3)");
  }
}

TEST(InputFiles, FieldCountFollowsTheHeader) {
  for (const Format& f : formats()) {
    const std::string n = std::to_string(f.columns.size());
    expect_error(f, file_with(f, 1, row(f, "1") + ",0"), 4, "",
                 "expected " + n + " fields (" + f.header() + "), got " +
                     std::to_string(f.columns.size() + 1));
    expect_error(f, file_with(f, 1, "1,0"), 4, "",
                 "expected " + n + " fields (" + f.header() + "), got 2");
  }
}

TEST(InputFiles, RowLimit) {
  for (const Format& f : formats()) {
    // A replay's limit is 10 million rows by default: its configurable limit is tested in
    // test_replay.cpp.
    if (f.name == "replay") continue;
    std::string text = f.header() + "\n";
    text.reserve(f.max_rows * 2 * f.columns.size() + 16 * f.max_rows);
    for (std::size_t i = 0; i <= f.max_rows; ++i)
      text += row(f, std::to_string(static_cast<double>(i) / 100.0)) + "\n";
    expect_error(f, text, f.max_rows + 2, "",
                 "too many data rows (limit " + std::to_string(f.max_rows) + " rows)");
  }
}

TEST(InputFiles, CrlfByteOrderMarkCommentsAndSpacingAreAcceptedAlike) {
  for (const Format& f : formats()) {
    SCOPED_TRACE(f.name);
    std::string text = "\xEF\xBB\xBF# comment\r\n\r\n  ";
    text += f.header() + "\t\r\n";
    for (int i = 0; i < 3; ++i)
      text.append(" ").append(row(f, std::to_string(i))).append(" \r\n  # x\r\n");
    EXPECT_NO_THROW(f.parse(text));
  }
}

TEST(InputFiles, UnreadableFilesAreLineZero) {
  const fs::path missing = fs::temp_directory_path() / "craneassist_no_such_input_file.csv";
  for (const Format& f : formats()) {
    SCOPED_TRACE(f.name);
    try {
      f.load(missing);
      ADD_FAILURE() << "accepted";
    } catch (const FileError& e) {
      EXPECT_EQ(std::string(e.what()), missing.string() + ": file not found");
      EXPECT_EQ(e.line(), 0u);
      EXPECT_EQ(e.field(), "");
    }
    try {
      f.load(fs::temp_directory_path());
      ADD_FAILURE() << "accepted";
    } catch (const FileError& e) {
      EXPECT_EQ(e.reason(), "cannot read file: is a directory");
    }
  }
}

TEST(InputFiles, ErrorsInAFileNameThePath) {
  const fs::path file =
      fs::temp_directory_path() /
      ("craneassist_test_input_" + std::to_string(std::random_device{}()) + ".csv");
  for (const Format& f : formats()) {
    SCOPED_TRACE(f.name);
    {
      std::ofstream out(file, std::ios::binary);
      out << file_with(f, 2, row(f, "2", 1, "abc"));
    }
    try {
      f.load(file);
      ADD_FAILURE() << "accepted";
    } catch (const FileError& e) {
      EXPECT_EQ(std::string(e.what()),
                file.string() + ":5: field '" + f.columns[1] + "': not a number: 'abc'");
    }
  }
  fs::remove(file);
}

// Every input file is read with a bound (craneassist/files/text_file.hpp, 64 MiB for the CSV
// formats): a larger regular file is refused by its size, and a file that states no size
// (/dev/zero) one byte past the bound, instead of the reader growing until the memory runs out.
TEST(InputFiles, AFileOverTheSizeLimitIsRefused) {
  const fs::path big = fs::temp_directory_path() /
                       ("craneassist_test_big_" + std::to_string(std::random_device{}()) + ".csv");
  {
    std::ofstream out(big, std::ios::binary);
    out << "t,v_x,v_y,v_z\n0,0,0,0\n";
  }
  fs::resize_file(big, files::kMaxCsvBytes + 1);  // sparse: no 64 MiB written
  for (const Format& f : formats()) {
    SCOPED_TRACE(f.name);
    const std::string kind = f.name == "replay" ? "replay"
                             : f.name == "path" ? "tip path"
                                                : "joint trajectory";
    for (const fs::path& file : {big, fs::path("/dev/zero")}) {
      try {
        f.load(file);
        ADD_FAILURE() << "accepted " << file;
      } catch (const FileError& e) {
        EXPECT_EQ(std::string(e.what()),
                  file.string() + ": larger than 64 MiB (the limit for " + kind + " files)");
        EXPECT_EQ(e.line(), 0u);
      }
    }
  }
  fs::remove(big);
}

// The bounded read itself: a file of the limit's size is read, one byte more is not; a FIFO
// states no size, and what its writer sends is read up to the bound.
TEST(InputFiles, TheBoundedReadStopsOneBytePastTheLimit) {
  const std::string name = "craneassist_test_bound_" + std::to_string(std::random_device{}());
  const fs::path at_limit = fs::temp_directory_path() / (name + ".csv");
  {
    std::ofstream out(at_limit, std::ios::binary);
    out << "t,v_x,v_y,v_z\n0,0,0,0\n";
    out << std::string(1000 - 22, '\n');
  }
  EXPECT_EQ(files::read_text_file(at_limit, 1000, "test").size(), 1000u);
  EXPECT_THROW(files::read_text_file(at_limit, 999, "test"), files::ReadError);
  EXPECT_EQ(Replay::load_file(at_limit).rows().size(), 1u);
  fs::remove(at_limit);

  const fs::path fifo = fs::temp_directory_path() / (name + ".fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto send = [&](std::string text) {
    return std::thread([&fifo, text] { std::ofstream(fifo, std::ios::binary) << text; });
  };
  std::thread writer = send("t,v_x,v_y,v_z\n0,0.1,0,0\n1,0,0,0\n");
  EXPECT_EQ(Replay::load_file(fifo).rows().size(), 2u);
  writer.join();
  writer = send(std::string(2000, 'x'));  // fits the pipe's buffer: the writer never blocks
  try {
    files::read_text_file(fifo, 1000, "test");
    ADD_FAILURE() << "accepted";
  } catch (const files::ReadError& e) {
    EXPECT_EQ(std::string(e.what()),
              fifo.string() + ": larger than 1000 bytes (the limit for test files)");
  }
  writer.join();
  fs::remove(fifo);
}

}  // namespace
}  // namespace craneassist::input
