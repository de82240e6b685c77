// `craneassist echo` and `craneassist dashboard` (dds::run_echo, dds::run_dashboard) against a
// TelemetryPublisher in the same process, over DDS, and against raw writers of malformed samples
// (dds_raw_writer.hpp). Each test has its own domain (150..159) so parallel test runs never see
// each other's samples.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/dds/command_writer.hpp"
#include "craneassist/dds/telemetry_publisher.hpp"
#include "craneassist/dds/tools.hpp"
#include "dds_raw_writer.hpp"
#include "dds_test_frames.hpp"

// Under AddressSanitizer: Debian's Fast DDS 2.9 (libfastrtps, not instrumented) deletes the
// statistics part of each DataReader with a mismatched size when the reader goes away
// (new-delete-type-mismatch inside RTPSReader::~RTPSReader). Not our code; every other check
// stays on, and the environment's ASAN_OPTIONS still override this.
extern "C" const char* __asan_default_options() {
  return "new_delete_type_mismatch=0";
}

namespace craneassist {
namespace {

// Publishes test_frame(cycle) at 100 Hz until destroyed; `tweak` changes each frame.
class BackgroundPublisher {
 public:
  explicit BackgroundPublisher(int domain, std::function<void(dds::TelemetryFrame&)> tweak = {})
      : publisher_(settings(domain), test::test_telemetry_info()), tweak_(std::move(tweak)) {
    thread_ = std::thread([this] { run(); });
  }
  ~BackgroundPublisher() {
    stop_.store(true);
    thread_.join();
    publisher_.close();
  }
  BackgroundPublisher(const BackgroundPublisher&) = delete;
  BackgroundPublisher& operator=(const BackgroundPublisher&) = delete;

 private:
  static config::TelemetryConfig settings(int domain) {
    config::TelemetryConfig c = config::default_telemetry_config();
    c.domain_id = domain;
    c.participant_name = "test_dds_tools";
    return c;
  }
  void run() {
    for (std::uint64_t cycle = 0; !stop_.load(); ++cycle) {
      dds::TelemetryFrame f = test::test_frame(cycle);
      if (tweak_) tweak_(f);
      publisher_.push(f);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

  dds::TelemetryPublisher publisher_;
  std::function<void(dds::TelemetryFrame&)> tweak_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// stdout and stderr of a tool, in temporary files.
class Captured {
 public:
  Captured() : out(std::tmpfile()), err(std::tmpfile()) {}
  ~Captured() {
    std::fclose(out);
    std::fclose(err);
  }
  Captured(const Captured&) = delete;
  Captured& operator=(const Captured&) = delete;
  std::string out_text() const { return read(out); }
  std::string err_text() const { return read(err); }

  std::FILE* out;
  std::FILE* err;

 private:
  static std::string read(std::FILE* f) {
    std::fflush(f);
    std::rewind(f);
    std::string s;
    char buf[4096];
    std::size_t n = 0;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
    return s;
  }
};

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// One CSV line's cells (RFC 4180 quotes).
std::vector<std::string> csv_cells(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cells.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cells.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      cells.emplace_back();
    } else {
      cells.back() += c;
    }
  }
  return cells;
}

// Header line and rows of a CSV echo, as column -> value maps.
std::vector<std::map<std::string, std::string>> csv_rows(const std::string& text) {
  const auto lines = lines_of(text);
  std::vector<std::map<std::string, std::string>> rows;
  if (lines.empty()) return rows;
  const auto header = csv_cells(lines[0]);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const auto cells = csv_cells(lines[i]);
    EXPECT_EQ(cells.size(), header.size()) << lines[i];
    std::map<std::string, std::string> row;
    for (std::size_t c = 0; c < header.size() && c < cells.size(); ++c) row[header[c]] = cells[c];
    rows.push_back(row);
  }
  return rows;
}

dds::EchoOptions echo_options(const std::string& topic, int domain, const Captured& io,
                              dds::EchoFormat format = dds::EchoFormat::kText) {
  dds::EchoOptions o;
  o.topic = topic;
  o.domain_id = domain;
  o.format = format;
  o.count = 3;
  o.timeout_s = 5.0;
  o.out = io.out;
  o.err = io.err;
  return o;
}

dds::DashboardOptions dashboard_options(int domain, bool once, double timeout_s,
                                        const Captured& io) {
  dds::DashboardOptions o;
  o.domain_id = domain;
  o.once = once;
  o.timeout_s = timeout_s;
  o.out = io.out;
  o.err = io.err;
  return o;
}

class DdsTools : public ::testing::Test {
 protected:
  void SetUp() override { dds::reset_stop(); }
};

TEST_F(DdsTools, EchoPrintsThreeSamplesOfEveryTelemetryTopic) {
  BackgroundPublisher publisher(150);
  // A line of each topic's text, with the publisher's value and its unit.
  const std::map<std::string, std::vector<std::string>> expected = {
      {"status",
       {"active_limit: power", "deadman: true", "tip_speed_m_s: 0.5 m/s", "stop_reason: \"\"",
        "crane: Test crane", "avail_speed_m_s: 1.25 m/s", "avail_speed_resolved_m_s: 1 m/s",
        "polytope_dim: 3", "polytope_volume_m3_s3: 51.51 m^3/s^3",
        "polytope_area_m2_s2: 0 m^2/s^2"}},
      {"joints",
       {"names: [slew, lift, tilt, extension]", "prismatic: [false, false, false, true]",
        "q: [0.523599 rad, 0.349066 rad, -0.785398 rad, 1.25 m]",
        "cylinder_pos_m: [0.5, 1.1, 0.9, 1.25] m", "tip_m: [5, 2.5, -0.75] m"}},
      {"hydraulics",
       {"power_w: 12500 W", "power_limit_w: 35000 W", "flow_m3_s: 0.001 m^3/s",
        "pressure_pa: 1.25e+07 Pa", "pump_mode: load-sensing"}},
      {"craneassist/command_path",  // the DDS name works too
       {"scale: 0.8", "command_m_s: [0.375, 0.5, 0] m/s", "sdot: 0.5 1/s"}},
  };
  for (const auto& [topic, fields] : expected) {
    SCOPED_TRACE(topic);
    Captured io;
    ASSERT_EQ(dds::run_echo(echo_options(topic, 150, io)), dds::kToolOk) << io.err_text();
    const std::string out = io.out_text();
    EXPECT_EQ(count_of(out, "---\n"), 3u) << out;
    EXPECT_EQ(count_of(out, "header:\n  cycle: "), 3u) << out;
    for (const auto& field : fields) EXPECT_NE(out.find(field + "\n"), std::string::npos) << field;
    // "matched" only once samples flow: discovery alone does not prove the writer matched us.
    EXPECT_NE(io.err_text().find("discovered 1 writer after"), std::string::npos) << io.err_text();
    EXPECT_NE(io.err_text().find("receiving, first sample after"), std::string::npos)
        << io.err_text();
    EXPECT_EQ(io.err_text().find("matched"), std::string::npos) << io.err_text();
  }
}

TEST_F(DdsTools, EchoCsvHeaderAndValuesRoundTrip) {
  BackgroundPublisher publisher(151, [](dds::TelemetryFrame& f) {
    f.stop_reason = "input stale, \"120 ms\"";  // needs CSV quoting
    f.pump_power_w = 12345.678;
  });
  {
    Captured io;
    auto o = echo_options("joints", 151, io, dds::EchoFormat::kCsv);
    ASSERT_EQ(dds::run_echo(o), dds::kToolOk) << io.err_text();
    const auto lines = lines_of(io.out_text());
    ASSERT_EQ(lines.size(), 4u) << io.out_text();
    EXPECT_EQ(lines[0].rfind("cycle,t_s,stamp_ns,q_slew,q_lift,q_tilt,q_extension,q_ref_slew,", 0),
              0u)
        << lines[0];
    EXPECT_NE(lines[0].find(",tip_m_x,tip_m_y,tip_m_z,tip_v_m_s_x,tip_v_m_s_y,tip_v_m_s_z"),
              std::string::npos)
        << lines[0];
    const auto rows = csv_rows(io.out_text());
    ASSERT_EQ(rows.size(), 3u);
    for (const auto& row : rows) {
      EXPECT_DOUBLE_EQ(std::stod(row.at("q_extension")), 1.25);
      EXPECT_NEAR(std::stod(row.at("q_slew")), 30.0 * test::kTestPi / 180.0, 1e-8);
      EXPECT_DOUBLE_EQ(std::stod(row.at("cylinder_pos_m_lift")), 1.1);
      EXPECT_DOUBLE_EQ(std::stod(row.at("tip_m_z")), -0.75);
      EXPECT_DOUBLE_EQ(std::stod(row.at("load_pressure_pa_lift")), 12.5e6);
      EXPECT_NEAR(std::stod(row.at("t_s")), std::stod(row.at("cycle")) * test::kTestDt, 1e-9);
    }
    EXPECT_LT(std::stoull(rows[0].at("cycle")), std::stoull(rows[2].at("cycle")));
  }
  {
    Captured io;
    auto o = echo_options("hydraulics", 151, io, dds::EchoFormat::kCsv);
    ASSERT_EQ(dds::run_echo(o), dds::kToolOk) << io.err_text();
    const auto rows = csv_rows(io.out_text());
    ASSERT_EQ(rows.size(), 3u) << io.out_text();
    EXPECT_DOUBLE_EQ(std::stod(rows[0].at("power_w")), 12345.678);
    EXPECT_DOUBLE_EQ(std::stod(rows[0].at("flow_limit_m3_s")), 2e-3);
    EXPECT_EQ(rows[0].at("pump_mode"), "load-sensing");
  }
  {
    Captured io;
    auto o = echo_options("status", 151, io, dds::EchoFormat::kCsv);
    o.count = 1;
    ASSERT_EQ(dds::run_echo(o), dds::kToolOk) << io.err_text();
    const auto rows = csv_rows(io.out_text());
    ASSERT_EQ(rows.size(), 1u) << io.out_text();
    EXPECT_EQ(rows[0].at("stop_reason"), "input stale, \"120 ms\"") << io.out_text();
    EXPECT_EQ(rows[0].at("crane"), "Test crane");
    EXPECT_EQ(rows[0].at("deadman"), "1");
  }
}

// operator_command from a writer without DDS Security (the crane's command input, when on,
// runs with security; a plain subscriber like echo sees only such an insecure writer).
TEST_F(DdsTools, EchoPrintsOperatorCommands) {
  dds::CommandWriterOptions wo;
  wo.domain_id = 157;
  wo.insecure = true;
  wo.sender = "test operator";
  dds::CommandWriter writer(wo);
  std::atomic<bool> stop{false};
  std::thread sender([&] {
    while (!stop.load()) {
      writer.write({0.25, -0.5, 0.125}, true);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  Captured text, csv;
  EXPECT_EQ(dds::run_echo(echo_options("operator_command", 157, text)), dds::kToolOk)
      << text.err_text();
  auto o = echo_options("craneassist/operator_command", 157, csv, dds::EchoFormat::kCsv);
  EXPECT_EQ(dds::run_echo(o), dds::kToolOk) << csv.err_text();
  stop.store(true);
  sender.join();

  const std::string out = text.out_text();
  EXPECT_EQ(count_of(out, "---\n"), 3u) << out;
  for (const char* field : {"sender: test operator\n", "v_m_s: [0.25, -0.5, 0.125] m/s\n",
                            "deadman: true\n", "seq: "}) {
    EXPECT_NE(out.find(field), std::string::npos) << field << "\n" << out;
  }
  const auto lines = lines_of(csv.out_text());
  ASSERT_EQ(lines.size(), 4u) << csv.out_text();
  EXPECT_EQ(lines[0], "seq,sender,v_m_s_x,v_m_s_y,v_m_s_z,deadman");
  const auto rows = csv_rows(csv.out_text());
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].at("sender"), "test operator");
  EXPECT_DOUBLE_EQ(std::stod(rows[0].at("v_m_s_z")), 0.125);
  EXPECT_GT(std::stoull(rows[1].at("seq")), std::stoull(rows[0].at("seq")));
}

TEST_F(DdsTools, EchoUnknownTopicIsAUsageErrorListingTheTopics) {
  Captured io;
  auto o = echo_options("warp", 0, io);
  EXPECT_EQ(dds::run_echo(o), dds::kToolUsage);
  const std::string err = io.err_text();
  EXPECT_NE(err.find("unknown topic 'warp'"), std::string::npos) << err;
  EXPECT_NE(err.find("status, joints, hydraulics, command_path, operator_command"),
            std::string::npos)
      << err;
  EXPECT_EQ(io.out_text(), "");
}

TEST_F(DdsTools, EchoTimeoutWithoutPublisher) {
  for (const std::string topic : {"status", "operator_command"}) {
    Captured io;
    auto o = echo_options(topic, 152, io);
    o.timeout_s = 0.5;
    const auto start = std::chrono::steady_clock::now();
    EXPECT_EQ(dds::run_echo(o), dds::kToolRuntime);
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(3));
    EXPECT_NE(io.err_text().find("no sample on craneassist/" + topic +
                                 " within 0.5 s on domain 152; is craneassist sim running with "
                                 "telemetry on?"),
              std::string::npos)
        << io.err_text();
    EXPECT_EQ(io.out_text(), "");
  }
}

TEST_F(DdsTools, EchoEndsCleanlyOnStopRequest) {
  Captured io;
  auto o = echo_options("status", 153, io);
  o.count = 0;
  o.timeout_s = 0.0;  // would wait forever
  std::thread stopper([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    dds::request_stop();
  });
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(dds::run_echo(o), dds::kToolOk);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(3));
  stopper.join();
}

// The snapshot's lines for the test frame: pump against its limits, active limit, joints in
// deg and m, tip and its speed.
void expect_test_frame_snapshot(const std::string& out) {
  for (const char* text :
       {"craneassist dashboard   domain ",
        "Test crane   backend sim",
        "status    running",
        "stop reason   -",
        "input     replay",
        "deadman       ON",
        "limit     power",
        "pump limiter  none",
        "scale     0.80",
        "loop      worst start 120 us",
        "overruns      2",
        "power     [###########...................]   12.5 /   35.0 kW      36 %",
        "flow      [###############...............]   60.0 /  120.0 L/min   50 %",
        "pressure 12.5 MPa",
        "stick     [###############...............]  0.62 /  1.25 m/s available   50 %",
        "polytope  volume 51.51 m^3/s^3        along the chosen joint motion 1.00 m/s",
        "scale       448.5 kg weighed                  at 5.50 m reach  (simulated 450 kg)",
        "moment    [###############...............]   50 % of 897 kg rated",
        "command   x  +0.375  y  +0.500  z  +0.000 m/s",
        "joint       position     reference      cylinder",
        "slew            30.0 deg      30.5 deg     0.500 m",
        "lift            20.0 deg      20.5 deg     1.100 m",
        "tilt           -45.0 deg     -44.5 deg     0.900 m",
        "extension      1.250 m       1.300 m       1.250 m",
        "tip       x  +5.000  y  +2.500  z  -0.750 m   speed 0.50 m/s   error 3.0 mm",
        "age       status         0.",
        "          hydraulics     0."}) {
    EXPECT_NE(out.find(text), std::string::npos) << "missing: " << text << "\n" << out;
  }
  EXPECT_EQ(out.find('\033'), std::string::npos) << "escape codes in a plain snapshot";
  EXPECT_EQ(out.find("STALE"), std::string::npos);
  EXPECT_EQ(out.find("q or Ctrl-C quits"), std::string::npos);
}

// The dashboard on `domain` with the synthetic publisher there shows the test frame; out: what
// it printed.
void expect_dashboard_shows_the_test_frame(int domain, bool once, std::string& out) {
  BackgroundPublisher publisher(domain);
  Captured io;
  ASSERT_EQ(dds::run_dashboard(dashboard_options(domain, once, 5.0, io)), dds::kToolOk)
      << io.err_text();
  out = io.out_text();
  expect_test_frame_snapshot(out);
}

TEST_F(DdsTools, DashboardOnceShowsThePublishedFrame) {
  std::string out;
  expect_dashboard_shows_the_test_frame(154, true, out);
}

TEST_F(DdsTools, DashboardNotATerminalPrintsOneSnapshot) {
  std::string out;
  expect_dashboard_shows_the_test_frame(156, false, out);  // not --once, but stdout is a file
  EXPECT_EQ(count_of(out, "craneassist dashboard   domain 156"), 1u);
}

TEST_F(DdsTools, DashboardOnceTimeoutWithoutPublisher) {
  Captured io;
  EXPECT_EQ(dds::run_dashboard(dashboard_options(155, true, 0.5, io)), dds::kToolRuntime);
  EXPECT_NE(io.err_text().find("no sample on craneassist/status, craneassist/joints, "
                               "craneassist/hydraulics, craneassist/command_path within 0.5 s on "
                               "domain 155; is craneassist sim running with telemetry on?"),
            std::string::npos)
      << io.err_text();
  EXPECT_EQ(io.out_text(), "");
}

// Writes samples of `topic` every 10 ms once a reader has matched: for `bad_only_s` only
// malformed ones (every kind the type can have), then each round the malformed ones and one
// well-formed sample (telemetry_payload: crane "Raw crane"; operator_command: sender
// "raw-operator").
class MalformedWriter {
 public:
  MalformedWriter(int domain, dds::Topic topic, double bad_only_s = 0.5)
      : writer_(options(domain, topic)), topic_(topic), bad_only_s_(bad_only_s) {
    thread_ = std::thread([this] { run(); });
  }
  ~MalformedWriter() {
    stop_.store(true);
    thread_.join();
  }
  MalformedWriter(const MalformedWriter&) = delete;
  MalformedWriter& operator=(const MalformedWriter&) = delete;

  std::uint64_t malformed_written() const { return malformed_.load(); }

 private:
  static test::RawWriterOptions options(int domain, dds::Topic topic) {
    test::RawWriterOptions o;
    o.domain_id = domain;
    o.topic = topic;
    return o;
  }
  void run() {
    while (!stop_.load() && writer_.matched_readers() == 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    const auto start = std::chrono::steady_clock::now();
    for (std::uint64_t n = 1; !stop_.load(); ++n) {
      for (test::Malformation m : test::malformations_of(topic_)) {
        writer_.write(test::malformed_payload(topic_, m));
        malformed_.fetch_add(1);
      }
      if (std::chrono::steady_clock::now() - start > std::chrono::duration<double>(bad_only_s_)) {
        writer_.write(topic_ == dds::Topic::kOperatorCommand
                          ? test::operator_command_payload(n, "raw-operator", {0.1, 0.2, 0.3}, true)
                          : test::telemetry_payload(topic_, n));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

  test::RawWriter writer_;
  dds::Topic topic_;
  double bad_only_s_;
  std::atomic<std::uint64_t> malformed_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// Malformed samples (a bool byte of 2, a bad encapsulation: Fast CDR throws while echo takes
// them; a cut-off body; joints over their bound) are dropped and counted; echo prints only the
// well-formed ones and says how many it dropped.
TEST_F(DdsTools, EchoDropsMalformedSamplesOfEveryTopic) {
  const std::map<dds::Topic, std::string> expected = {
      {dds::Topic::kStatus, "crane: Raw crane\n"},
      {dds::Topic::kJoints, "names: [j0, j1, j2, j3]\n"},
      {dds::Topic::kHydraulics, "pump_mode: load-sensing\n"},
      {dds::Topic::kCommandPath, "input_source: dds\n"},
      {dds::Topic::kOperatorCommand, "sender: raw-operator\n"},
  };
  for (const auto& [topic, line] : expected) {
    const std::string name(dds::topic_info(topic).short_name);
    SCOPED_TRACE(name);
    MalformedWriter writer(158, topic);
    Captured io;
    ASSERT_EQ(dds::run_echo(echo_options(name, 158, io)), dds::kToolOk) << io.err_text();
    const std::string out = io.out_text();
    EXPECT_EQ(count_of(out, "---\n"), 3u) << out;
    EXPECT_EQ(count_of(out, line), 3u) << out;
    const std::string err = io.err_text();
    EXPECT_EQ(count_of(err, "dropped a malformed sample (cannot be deserialized); echo goes on"),
              1u)
        << err;
    EXPECT_NE(err.find("malformed samples dropped"), std::string::npos) << err;
    EXPECT_GT(writer.malformed_written(), 0u);
  }
}

// The dashboard takes its samples on Fast DDS's threads: malformed ones there must neither end
// the process nor show; the view counts them per topic.
TEST_F(DdsTools, DashboardDropsMalformedSamplesAndCountsThem) {
  std::vector<std::unique_ptr<MalformedWriter>> writers;
  for (dds::Topic topic : {dds::Topic::kStatus, dds::Topic::kJoints, dds::Topic::kHydraulics,
                           dds::Topic::kCommandPath}) {
    writers.push_back(std::make_unique<MalformedWriter>(159, topic));
  }
  Captured io;
  ASSERT_EQ(dds::run_dashboard(dashboard_options(159, true, 10.0, io)), dds::kToolOk)
      << io.err_text();
  const std::string out = io.out_text();
  EXPECT_NE(out.find("Raw crane   backend sim"), std::string::npos) << out;
  EXPECT_NE(out.find("\nj3        "), std::string::npos) << out;
  const auto line = out.find("dropped   ");
  ASSERT_NE(line, std::string::npos) << out;
  const std::string dropped = out.substr(line, out.find('\n', line) - line);
  for (const char* topic : {"status", "joints", "hydraulics", "command_path"}) {
    EXPECT_NE(dropped.find(std::string(topic) + " "), std::string::npos) << dropped;
    EXPECT_EQ(dropped.find(std::string(topic) + " 0"), std::string::npos) << dropped;
  }
}

}  // namespace
}  // namespace craneassist
