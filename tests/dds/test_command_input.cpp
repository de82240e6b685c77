// The DDS command input (docs/remote-commands.md): the settings reader's errors for the
// command input's security files, and DdsCommandSource's states against a CommandWriter in the
// same process, with certificates made by tools/dds-security/make-certs.sh; what it does with
// malformed and replayed samples, from a raw writer with the operator's identity
// (dds_raw_writer.hpp), and who holds the command when two operators send. Each DDS test has its
// own domain (181..188).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>

#include "craneassist/config/config_error.hpp"
#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/dds/command_source.hpp"
#include "craneassist/dds/command_writer.hpp"
#include "craneassist/input/input_monitor.hpp"
#include "dds_raw_writer.hpp"

// Under AddressSanitizer: Debian's Fast DDS 2.9 (not instrumented) deletes its statistics
// listeners with a mismatched size at every participant's teardown, and leaks OpenSSL objects on
// a failed handshake (tests/lsan-fastdds.supp). Environment options still override these.
extern "C" const char* __asan_default_options() {
  return "new_delete_type_mismatch=0";
}
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libcrypto.so\n";
}

namespace craneassist {
namespace {

namespace fs = std::filesystem;
using input::SourceState;

fs::path temp_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("craneassist-test-command-input-" + name + "-" +
                                                    std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The certificates of make-certs.sh, once per test program (removed at exit).
struct RemoveAtExit {
  fs::path dir;
  ~RemoveAtExit() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

const fs::path& certs() {
  static const RemoveAtExit made{[] {
    const fs::path d = temp_dir("certs");
    const std::string cmd = std::string(CRANEASSIST_SOURCE_DIR) +
                            "/tools/dds-security/make-certs.sh '" + d.string() + "' >/dev/null";
    if (std::system(cmd.c_str()) != 0) throw std::runtime_error("make-certs.sh failed");
    return d;
  }()};
  return made.dir;
}

std::string error_of(const std::string& yaml, const fs::path& base) {
  try {
    config::parse_telemetry_config(yaml, "settings.yaml", base);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

const char* kHeader = "format: craneassist-telemetry/1\n";

TEST(CommandInputSettings, PartialSecurityFilesNameFileLineAndField) {
  const fs::path dir = temp_dir("partial");
  for (const char* f : {"ca.pem", "crane.pem", "crane.key"}) std::ofstream(dir / f) << "x";
  const std::string yaml = std::string(kHeader) +
                           "commands:\n"
                           "  enabled: false\n"
                           "  security:\n"
                           "    identity_ca: ca.pem\n"
                           "    identity_certificate: crane.pem\n"
                           "    private_key: crane.key\n";
  EXPECT_EQ(error_of(yaml, dir),
            "settings.yaml:5: field 'commands.security': give every file (identity_ca, "
            "identity_certificate, private_key, permissions_ca, governance, permissions) or none; "
            "missing: permissions_ca, governance, permissions (docs/remote-commands.md)");
  fs::remove_all(dir);
}

TEST(CommandInputSettings, EnabledWithoutSecurityIsRejected) {
  const std::string yaml = std::string(kHeader) +
                           "commands:\n"
                           "  enabled: true\n";
  const std::string e = error_of(yaml, {});
  EXPECT_NE(e.find("settings.yaml:3: field 'commands.enabled': the DDS command input needs DDS "
                   "Security"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("docs/remote-commands.md"), std::string::npos) << e;
}

TEST(CommandInputSettings, MissingFileNamesItsField) {
  const std::string yaml = std::string(kHeader) +
                           "commands:\n"
                           "  security:\n"
                           "    identity_ca: nowhere/ca.pem\n";
  const std::string e = error_of(yaml, fs::temp_directory_path());
  EXPECT_NE(e.find("settings.yaml:4: field 'commands.security.identity_ca': no such file"),
            std::string::npos)
      << e;
}

TEST(CommandInputSettings, MadeFilesAreRelativeToTheSettingsFile) {
  const config::TelemetryConfig c = config::load_telemetry_config(certs() / "crane.yaml");
  EXPECT_TRUE(c.commands.enabled);
  ASSERT_TRUE(c.commands.security.complete());
  EXPECT_EQ(fs::path(c.commands.security.permissions), certs() / "crane-permissions.p7s");
  EXPECT_NO_THROW(dds::check_command_input_settings(c));
}

TEST(CommandInputSettings, TheInputRefusesToStartWithoutSecurity) {
  const config::TelemetryConfig c = config::default_telemetry_config();
  try {
    dds::check_command_input_settings(c);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("commands.enabled is not true"), std::string::npos) << what;
    EXPECT_NE(what.find("commands.security.identity_ca"), std::string::npos) << what;
    EXPECT_NE(what.find("docs/remote-commands.md"), std::string::npos) << what;
  }
  config::TelemetryConfig enabled = c;
  enabled.commands.enabled = true;  // as if the reader had let it through
  EXPECT_THROW(dds::DdsCommandSource source(enabled), std::invalid_argument);
}

TEST(CommandWriter, RefusesAnIncompleteIdentity) {
  dds::CommandWriterOptions o;
  o.security.identity_ca = "ca.pem";
  EXPECT_THROW(dds::CommandWriter w(o), std::invalid_argument);
  o.insecure = true;  // insecure and files: a mistake too
  EXPECT_THROW(dds::CommandWriter w(o), std::invalid_argument);
}

config::TelemetryConfig settings_of(const std::string& identity, int domain) {
  config::TelemetryConfig c = config::load_telemetry_config(certs() / (identity + ".yaml"));
  c.domain_id = domain;
  return c;
}

dds::CommandWriterOptions writer_options(const std::string& identity, int domain) {
  const config::TelemetryConfig c = settings_of(identity, domain);
  dds::CommandWriterOptions o;
  o.domain_id = domain;
  o.topic = c.commands.topic;
  o.security = c.commands.security;
  o.sender = "unit-test";
  return o;
}

// Polls until the state is `want` or `timeout_s` passes; the last sample in `out`.
SourceState poll_until(dds::DdsCommandSource& source, SourceState want, double timeout_s,
                       input::OperatorCommand& out, dds::CommandWriter* writer = nullptr) {
  const double end = input::steady_now_s() + timeout_s;
  SourceState s = source.poll(out);
  while (s != want && input::steady_now_s() < end) {
    if (writer != nullptr) writer->write({0.1, 0.0, 0.0}, false);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    s = source.poll(out);
  }
  return s;
}

TEST(DdsCommandSource, NoDataThenSamplesThenStaleThenDisconnected) {
  dds::DdsCommandSource source(settings_of("crane", 181));
  EXPECT_STREQ(source.name(), "dds");
  input::OperatorCommand out;
  out.stamp_s = -1.0;
  EXPECT_EQ(source.poll(out), SourceState::kNoData);
  EXPECT_EQ(out.stamp_s, -1.0);  // left unchanged

  auto writer = std::make_unique<dds::CommandWriter>(writer_options("operator", 181));
  // Discovery and authentication; the writer keeps sending meanwhile.
  ASSERT_EQ(poll_until(source, SourceState::kOk, 10.0, out, writer.get()), SourceState::kOk);
  EXPECT_GT(source.stats().matched_writers, 0);

  // A fresh sample: its values and a reception stamp on steady_clock.
  ASSERT_TRUE(writer->write({0.25, -0.1, 0.05}, true));
  const double sent = input::steady_now_s();
  double stamp = 0.0;
  for (int i = 0; i < 200; ++i) {
    source.poll(out);
    if (out.deadman) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(out.deadman);
  EXPECT_DOUBLE_EQ(out.v_m_s.x(), 0.25);
  EXPECT_DOUBLE_EQ(out.v_m_s.y(), -0.1);
  EXPECT_DOUBLE_EQ(out.v_m_s.z(), 0.05);
  EXPECT_NEAR(out.stamp_s, sent, 0.5);
  stamp = out.stamp_s;

  // No new sample: the same stamp (the monitor sees it go stale), still connected.
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  EXPECT_EQ(source.poll(out), SourceState::kOk);
  EXPECT_EQ(out.stamp_s, stamp);
  EXPECT_GT(input::steady_now_s() - out.stamp_s, 0.1);

  const dds::CommandInputStats s = source.stats();
  EXPECT_GE(s.samples, 2u);
  EXPECT_EQ(s.sender, "unit-test");
  EXPECT_EQ(s.non_finite, 0u);
  EXPECT_GE(s.first_match_s, 0.0);
  EXPECT_GE(s.first_sample_s, s.first_match_s);

  // The operator's participant goes away: disconnected, the last sample kept.
  writer.reset();
  EXPECT_EQ(poll_until(source, SourceState::kDisconnected, 5.0, out), SourceState::kDisconnected);
  EXPECT_EQ(out.stamp_s, stamp);
  EXPECT_EQ(source.stats().matched_writers, 0);
}

TEST(DdsCommandSource, NonFiniteSamplesArePassedOnAndCounted) {
  dds::DdsCommandSource source(settings_of("crane", 182));
  dds::CommandWriter writer(writer_options("operator", 182));
  input::OperatorCommand out;
  ASSERT_EQ(poll_until(source, SourceState::kOk, 10.0, out, &writer), SourceState::kOk);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(writer.write({nan, 0.0, 0.0}, true));
  for (int i = 0; i < 200 && source.stats().non_finite == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(source.stats().non_finite, 1u);
  source.poll(out);
  EXPECT_TRUE(std::isnan(out.v_m_s.x()));  // the input monitor stops the crane on it
}

TEST(DdsCommandSource, AnInsecureWriterNeverMatches) {
  dds::DdsCommandSource source(settings_of("crane", 183));
  dds::CommandWriterOptions o;
  o.domain_id = 183;
  o.insecure = true;
  dds::CommandWriter writer(o);
  input::OperatorCommand out;
  const double end = input::steady_now_s() + 2.0;
  while (input::steady_now_s() < end) {
    writer.write({0.3, 0.0, 0.0}, true);
    EXPECT_EQ(source.poll(out), SourceState::kNoData);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(source.stats().samples, 0u);
  EXPECT_EQ(source.stats().writer_matches, 0);
  EXPECT_EQ(writer.stats().first_match_s, -1.0);
}

TEST(DdsCommandSource, OneOperatorAtATime) {
  dds::DdsCommandSource source(settings_of("crane", 184));
  dds::CommandWriterOptions first_options = writer_options("operator", 184);
  first_options.sender = "first";
  dds::CommandWriter first(first_options);
  input::OperatorCommand out;
  ASSERT_EQ(poll_until(source, SourceState::kOk, 10.0, out, &first), SourceState::kOk);
  dds::CommandWriterOptions second_options = writer_options("operator", 184);
  second_options.sender = "second";
  dds::CommandWriter second(second_options);
  const double end = input::steady_now_s() + 10.0;
  while (source.stats().peak_matched_writers < 2 && input::steady_now_s() < end) {
    first.write({0.1, 0.0, 0.0}, false);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(source.stats().peak_matched_writers, 2);
  // Both send; the first holds the command, the second's samples are dropped.
  for (int i = 0; i < 20; ++i) {
    first.write({0.1, 0.0, 0.0}, false);
    second.write({-0.2, 0.0, 0.0}, true);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  source.poll(out);
  EXPECT_DOUBLE_EQ(out.v_m_s.x(), 0.1);
  EXPECT_FALSE(out.deadman);
  dds::CommandInputStats s = source.stats();
  EXPECT_EQ(s.sender, "first");
  EXPECT_GE(s.other_senders, 15u);
  // The first falls silent for longer than the stale timeout (0.1 s): the second may take over,
  // its deadman read released until it has sent it released.
  for (int i = 0; i < 70; ++i) {
    second.write({-0.2, 0.0, 0.0}, true);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  source.poll(out);
  EXPECT_DOUBLE_EQ(out.v_m_s.x(), -0.2);
  EXPECT_FALSE(out.deadman);
  EXPECT_EQ(source.stats().sender, "second");
  second.write({-0.2, 0.0, 0.0}, false);
  second.write({-0.2, 0.0, 0.0}, true);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  source.poll(out);
  EXPECT_TRUE(out.deadman);
  EXPECT_EQ(source.stats().owner_changes, 2);
}

// The operator's identity writing payloads of its own making to the crane's command input.
class RawOperator {
 public:
  explicit RawOperator(int domain, std::string sender = "raw-operator")
      : writer_(options(domain)), sender_(std::move(sender)) {}
  // A well-formed sample with the next seq.
  bool send(const std::array<double, 3>& v, bool deadman) {
    return writer_.write(test::operator_command_payload(++seq_, sender_, v, deadman));
  }
  bool send_raw(const test::Payload& payload) { return writer_.write(payload); }
  // A well-formed sample with this seq (the next send() continues after the highest so far).
  bool send_seq(std::uint64_t seq, const std::array<double, 3>& v, bool deadman) {
    seq_ = std::max(seq_, seq);
    return writer_.write(test::operator_command_payload(seq, sender_, v, deadman));
  }
  std::uint64_t seq() const { return seq_; }

 private:
  static test::RawWriterOptions options(int domain) {
    test::RawWriterOptions o;
    o.domain_id = domain;
    o.security = settings_of("operator", domain).commands.security;
    return o;
  }
  test::RawWriter writer_;
  std::string sender_;
  std::uint64_t seq_ = 0;
};

// The crane's side of a test: the source behind the input monitor, one cycle every 10 ms.
struct MonitoredSource {
  explicit MonitoredSource(dds::DdsCommandSource& s,
                           const input::InputMonitorSettings& settings = {})
      : source(s), monitor(settings) {}
  const input::MonitorOutput& cycle() {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    state = source.poll(sample);
    monitor.update(state, sample, input::steady_now_s(), out);
    return out;
  }
  dds::DdsCommandSource& source;
  input::InputMonitor monitor;
  input::OperatorCommand sample;
  input::MonitorOutput out;
  SourceState state = SourceState::kNoData;
};

// Sends released-deadman samples until the source has one (discovery and the DDS Security
// handshake), then `released` more cycles of them, then `pressed` cycles moving at v (the
// monitor passes the command once the deadman has been held for 0.3 s).
void arm_and_move(RawOperator& op, MonitoredSource& crane, const std::array<double, 3>& v,
                  int released = 20, int pressed = 50) {
  const double end = input::steady_now_s() + 10.0;
  while (crane.state != SourceState::kOk && input::steady_now_s() < end) {
    op.send({0.0, 0.0, 0.0}, false);
    crane.cycle();
  }
  ASSERT_EQ(crane.state, SourceState::kOk) << "no sample from the raw operator within 10 s";
  for (int i = 0; i < released; ++i) {
    op.send({0.0, 0.0, 0.0}, false);
    crane.cycle();
  }
  for (int i = 0; i < pressed; ++i) {
    op.send(v, true);
    crane.cycle();
  }
}

// Waits (the first operator sending) until the source has matched two writers.
void wait_for_two_writers(dds::DdsCommandSource& source, RawOperator& first, MonitoredSource& crane,
                          const std::array<double, 3>& v) {
  const double end = input::steady_now_s() + 10.0;
  while (source.stats().peak_matched_writers < 2 && input::steady_now_s() < end) {
    first.send(v, true);
    crane.cycle();
  }
  ASSERT_EQ(source.stats().peak_matched_writers, 2);
}

// The crane's command input on `domain`, its input monitor (the given stale timeout) and an
// operator armed and moving at v.
struct ArmedOperator {
  ArmedOperator(int domain, const std::array<double, 3>& v, std::string sender = "raw-operator",
                double stale_timeout_s = input::InputMonitorSettings{}.stale_timeout_s)
      : monitor(monitor_settings(stale_timeout_s)),
        source(settings_of("crane", domain), stale_timeout_s),
        first(domain, std::move(sender)),
        crane(source, monitor) {
    arm_and_move(first, crane, v);
  }
  static input::InputMonitorSettings monitor_settings(double stale_timeout_s) {
    input::InputMonitorSettings m;
    m.stale_timeout_s = stale_timeout_s;
    return m;
  }
  input::InputMonitorSettings monitor;
  dds::DdsCommandSource source;
  RawOperator first;
  MonitoredSource crane;
};

// The same with the first operator "first", then a second operator ("second") whose writer the
// input has matched too.
struct TwoOperators : ArmedOperator {
  TwoOperators(int domain, double stale_timeout_s, const std::array<double, 3>& v)
      : ArmedOperator(domain, v, "first", stale_timeout_s), second(domain, "second") {
    wait_for_two_writers(source, first, crane, v);
  }
  RawOperator second;
};

// A malformed OperatorCommand (a bool byte of 2, a bad encapsulation: Fast CDR throws on Fast
// DDS's thread; a cut-off body: Fast DDS 2.9 would hand over the part it read) is dropped and
// counted, never passed on: while only such samples arrive, the input goes stale and the
// monitor stops the crane. The source survives and takes the next good sample.
TEST(DdsCommandSource, MalformedSamplesAreDroppedCountedAndGoStale) {
  ArmedOperator armed(185, {0.3, 0.0, 0.0});
  auto [source, op, crane] = std::tie(armed.source, armed.first, armed.crane);
  ASSERT_TRUE(crane.out.enabled) << input::to_string(crane.out.fault);
  const std::uint64_t good = source.stats().samples;

  // Only malformed samples for 0.6 s, each kind in turn; each says "deadman held, 0.3 m/s".
  const test::Malformation kinds[] = {test::Malformation::kTruncated, test::Malformation::kBadBool,
                                      test::Malformation::kBadEncapsulation};
  const double bad_start = input::steady_now_s();
  int sent = 0;
  double stopped_after = -1.0;
  while (input::steady_now_s() - bad_start < 0.6) {
    op.send_raw(test::malformed_payload(dds::Topic::kOperatorCommand, kinds[sent % 3]));
    ++sent;
    const input::MonitorOutput& o = crane.cycle();
    if (!o.enabled && stopped_after < 0.0) stopped_after = input::steady_now_s() - bad_start;
    if (stopped_after >= 0.0) {
      EXPECT_FALSE(o.enabled) << "the command passed again after the stop";
    }
  }
  EXPECT_EQ(crane.out.fault, input::InputFault::kStale) << input::to_string(crane.out.fault);
  EXPECT_GE(stopped_after, 0.09);
  EXPECT_LT(stopped_after, 0.3);
  // The last good sample stays what the source reports (now stale): nothing of the bad ones.
  EXPECT_DOUBLE_EQ(crane.sample.v_m_s.x(), 0.3);
  const dds::CommandInputStats s = source.stats();
  EXPECT_EQ(s.samples, good);
  EXPECT_GE(s.malformed, static_cast<std::uint64_t>(sent) / 2) << sent << " sent";
  EXPECT_LE(s.malformed, static_cast<std::uint64_t>(sent));

  // Good samples again: taken (the monitor wants a release and press, the deadman held 0.3 s
  // and the stop latched 1 s before motion).
  arm_and_move(op, crane, {0.0, 0.0, 0.2}, 5, 100);
  EXPECT_TRUE(crane.out.enabled) << input::to_string(crane.out.fault);
  EXPECT_DOUBLE_EQ(crane.sample.v_m_s.z(), 0.2);
  EXPECT_GT(source.stats().samples, good);
}

// A sample whose seq is not above what its writer sent before (an old sample replayed, or the
// latest repeated) is dropped and counted, per writer: another writer's seq starts afresh.
TEST(DdsCommandSource, ReplayedSamplesAreDroppedPerWriter) {
  ArmedOperator armed(186, {0.3, 0.0, 0.0});
  auto [source, op, crane] = std::tie(armed.source, armed.first, armed.crane);
  ASSERT_TRUE(crane.out.enabled) << input::to_string(crane.out.fault);
  const std::uint64_t latest = op.seq();
  ASSERT_GT(latest, 40u);
  const std::uint64_t good = source.stats().samples;

  // An old sample (seq 10, pressed, moving the other way), the latest once more, seq 0: dropped,
  // the source still reports the latest good sample.
  op.send_seq(10, {-0.5, 0.0, 0.0}, true);
  crane.cycle();
  op.send_seq(latest, {-0.5, 0.0, 0.0}, true);
  crane.cycle();
  op.send_seq(0, {-0.5, 0.0, 0.0}, true);
  for (int i = 0; i < 5; ++i) crane.cycle();
  EXPECT_DOUBLE_EQ(crane.sample.v_m_s.x(), 0.3);
  dds::CommandInputStats s = source.stats();
  EXPECT_EQ(s.replayed, 3u);
  EXPECT_EQ(s.samples, good);
  // Only replays: no fresh sample, the input goes stale.
  for (int i = 0; i < 20; ++i) {
    op.send_seq(20 + static_cast<std::uint64_t>(i), {-0.5, 0.0, 0.0}, true);
    crane.cycle();
  }
  EXPECT_EQ(crane.out.fault, input::InputFault::kStale) << input::to_string(crane.out.fault);
  EXPECT_EQ(source.stats().replayed, 23u);
  // A higher seq is taken (the gap counts as lost).
  const std::uint64_t lost_before = source.stats().lost;
  op.send_seq(1000000, {0.0, 0.0, 0.1}, false);
  for (int i = 0; i < 5; ++i) crane.cycle();
  EXPECT_DOUBLE_EQ(crane.sample.v_m_s.z(), 0.1);
  EXPECT_EQ(source.stats().samples, good + 1);
  EXPECT_EQ(source.stats().lost, lost_before + 1000000 - latest - 1);

  // Another writer, once the first has been silent for 1 s, counts from 1: its seq is its own,
  // not held against the first's.
  const std::uint64_t replayed_before = source.stats().replayed;
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  RawOperator second(186);
  const double end = input::steady_now_s() + 10.0;
  while (crane.sample.v_m_s.y() != 0.2 && input::steady_now_s() < end) {
    second.send({0.0, 0.2, 0.0}, false);
    crane.cycle();
  }
  EXPECT_DOUBLE_EQ(crane.sample.v_m_s.y(), 0.2);
  EXPECT_LT(second.seq(), 1000000u);
  EXPECT_EQ(source.stats().replayed, replayed_before);
  second.send_seq(1, {0.0, -0.2, 0.0}, false);  // its own first seq again
  for (int i = 0; i < 5; ++i) crane.cycle();
  EXPECT_DOUBLE_EQ(crane.sample.v_m_s.y(), 0.2);
  EXPECT_EQ(source.stats().replayed, replayed_before + 1);
}

// With a stale timeout longer than the old fixed 0.5 s: the second operator, sending with its
// deadman held all along, takes the command over only after the first has been silent for longer
// than the stale timeout, and its command passes only after it has released and pressed the
// deadman.
TEST(DdsCommandSource, TakeoverOnlyAfterTheStaleTimeoutAndWithReArm) {
  TwoOperators ops(187, 1.0, {0.3, 0.0, 0.0});
  auto [source, first, crane, second] = std::tie(ops.source, ops.first, ops.crane, ops.second);
  ASSERT_TRUE(crane.out.enabled) << input::to_string(crane.out.fault);

  // The first falls silent; the second sends, deadman held, moving the other way.
  const double silent_from = input::steady_now_s();
  double took_over_s = -1.0;
  int second_passed = 0;
  while (input::steady_now_s() - silent_from < 2.5) {
    second.send({-0.2, 0.0, 0.0}, true);
    const input::MonitorOutput& o = crane.cycle();
    if (crane.sample.v_m_s.x() < 0.0 && took_over_s < 0.0) {
      took_over_s = input::steady_now_s() - silent_from;
    }
    if (o.enabled && o.v_m_s.x() < 0.0) ++second_passed;
  }
  EXPECT_GT(took_over_s, 1.0);
  EXPECT_LT(took_over_s, 1.3);
  EXPECT_EQ(second_passed, 0) << "the second's command passed without a release and press";
  EXPECT_FALSE(crane.out.enabled);
  EXPECT_FALSE(crane.sample.deadman);  // read released until the second releases it
  dds::CommandInputStats s = source.stats();
  EXPECT_EQ(s.sender, "second");
  EXPECT_EQ(s.owner_changes, 2);
  EXPECT_GT(s.other_senders, 50u);  // its samples in the first second

  // The second releases and presses (and holds the deadman 0.3 s): now its command passes.
  for (int i = 0; i < 10; ++i) {
    second.send({-0.2, 0.0, 0.0}, false);
    crane.cycle();
  }
  EXPECT_FALSE(crane.out.enabled);
  for (int i = 0; i < 40; ++i) {
    second.send({-0.2, 0.0, 0.0}, true);
    crane.cycle();
  }
  EXPECT_TRUE(crane.out.enabled) << input::to_string(crane.out.fault);
  EXPECT_DOUBLE_EQ(crane.out.v_m_s.x(), -0.2);
}

// Two operators both sending: the first keeps the command every cycle, the second's samples
// are dropped; ownership never alternates.
TEST(DdsCommandSource, FightingOperatorsNeverAlternate) {
  // Stale timeout 0.3 s: margin for a test thread descheduled on a loaded machine.
  TwoOperators ops(188, 0.3, {0.1, 0.0, 0.0});
  auto [source, first, crane, second] = std::tie(ops.source, ops.first, ops.crane, ops.second);
  ASSERT_TRUE(crane.out.enabled) << input::to_string(crane.out.fault);
  int cycles = 0, first_held = 0;
  for (int i = 0; i < 200; ++i) {
    // Alternately first and second send first within a cycle; the second releases and presses.
    if (i % 2 == 0) {
      first.send({0.1, 0.0, 0.0}, true);
      second.send({-0.2, 0.0, 0.0}, i % 10 < 5);
    } else {
      second.send({-0.2, 0.0, 0.0}, i % 10 < 5);
      first.send({0.1, 0.0, 0.0}, true);
    }
    const input::MonitorOutput& o = crane.cycle();
    ++cycles;
    if (crane.sample.v_m_s.x() == 0.1 && o.enabled) ++first_held;
  }
  EXPECT_EQ(first_held, cycles);
  const dds::CommandInputStats s = source.stats();
  EXPECT_EQ(s.sender, "first");
  EXPECT_EQ(s.owner_changes, 1);
  EXPECT_GE(s.other_senders, 150u);
}

}  // namespace
}  // namespace craneassist
