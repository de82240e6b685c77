#include "remote_command.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "craneassist/config/config_error.hpp"
#include "craneassist/config/joystick_config.hpp"
#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/dds/command_writer.hpp"
#include "craneassist/input/keyboard_source.hpp"
#include "craneassist/input/replay.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"

namespace craneassist::cli {
namespace {

std::atomic<bool> g_stop{false};

extern "C" void on_remote_stop_signal(int) {
  g_stop.store(true);
  input::KeyboardSource::restore_terminal();
}

// Replay: the deadman is held released this long after a crane's reader matched, so the crane's
// input monitor sees a release before the press (it arms only on a fresh release and press).
constexpr double kLeadIn_s = 0.3;
// At the end: this many samples with the deadman released, so the crane stops on a released
// deadman rather than on a lost writer.
constexpr int kTailSamples = 5;

std::string default_sender() {
  const char* user = std::getenv("USER");
  char host[256] = "";
  if (gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
  return std::string(user != nullptr && *user != '\0' ? user : "operator") + "@" +
         (host[0] != '\0' ? host : "localhost");
}

void print_keys() {
  std::printf(
      "keys: space deadman on/off | w/s forward/back (x) | a/d left/right (z) | r/f up/down (y) "
      "| +/- speed | l latch | x stop axes | q quit\n");
}

}  // namespace

CLI::App* add_remote_command(CLI::App& cli, RemoteArgs& args) {
  auto* remote = cli.add_subcommand(
      "remote",
      "Remote operator console: send tip-velocity commands to `craneassist sim --input dds` "
      "over DDS Security, from the keyboard or a replay file (docs/remote-commands.md)");
  remote
      ->add_option("--telemetry-config", args.config_file,
                   "The operator's DDS settings: domain, transport and its identity in "
                   "commands.security (tools/dds-security/make-certs.sh makes operator.yaml)")
      ->check(CLI::ExistingFile);
  remote->add_option("--domain", args.domain, "DDS domain id (overrides the settings file)")
      ->check(CLI::Range(0, 232));
  remote
      ->add_option("--replay", args.replay_file,
                   "Send this replay CSV (docs/replay-format.md) at wall-clock time instead of "
                   "the keyboard; deadman held except in stop rows")
      ->check(CLI::ExistingFile);
  remote
      ->add_option("--joystick", args.joystick_file,
                   "Keyboard speeds and hold times from this mapping YAML (its axes are used in "
                   "the crane frame; default: the embedded config/joysticks/gamepad.yaml)")
      ->check(CLI::ExistingFile);
  remote
      ->add_option("--duration", args.duration_s,
                   "Seconds to send (default: keyboard until q or Ctrl-C; replay: its length)")
      ->check(FiniteRange(0.01, 1e6));
  remote->add_option("--rate", args.rate_hz, "Samples per second")
      ->check(FiniteRange(1.0, 1000.0))
      ->capture_default_str();
  remote
      ->add_option("--wait", args.wait_s,
                   "Replay: play after at most this long even if no crane's reader matched")
      ->check(FiniteRange(0.0, 600.0))
      ->capture_default_str();
  remote->add_option("--sender", args.sender,
                     "The sender name the crane shows (default: USER@host)");
  remote->add_flag("--insecure", args.insecure,
                   "Send WITHOUT DDS Security: only to show that a crane with the DDS command "
                   "input ignores an unauthenticated participant");
  return remote;
}

int run_remote_command(const RemoteArgs& args) {
  config::TelemetryConfig tcfg;
  config::JoystickConfig jcfg;
  std::optional<input::Replay> replay;
  try {
    tcfg = args.config_file.empty() ? config::default_telemetry_config()
                                    : config::load_telemetry_config(args.config_file);
    if (args.domain) tcfg.domain_id = *args.domain;
    jcfg = args.joystick_file.empty() ? config::default_joystick_config()
                                      : config::load_joystick_config(args.joystick_file);
    if (!args.replay_file.empty()) replay = input::Replay::load_file(args.replay_file);
  } catch (...) {
    return input_error_exit("replay");
  }
  const config::SecurityFiles& sec = tcfg.commands.security;
  if (!args.insecure && !sec.complete()) {
    spdlog::error(
        "craneassist remote needs the operator's DDS Security identity: --telemetry-config FILE "
        "whose commands.security gives every file ({}: {} not given). "
        "tools/dds-security/make-certs.sh OUTDIR makes OUTDIR/operator.yaml; see "
        "docs/remote-commands.md",
        tcfg.source_name, sec.missing());
    return kExitUsage;
  }
  if (!replay && !isatty(0)) {
    spdlog::error("the keyboard needs a terminal on stdin (or give --replay FILE)");
    return kExitUsage;
  }

  dds::CommandWriterOptions options;
  options.domain_id = tcfg.domain_id;
  options.transport = tcfg.transport;
  options.type_propagation = tcfg.type_propagation;
  options.topic = tcfg.commands.topic;
  options.insecure = args.insecure;
  if (!args.insecure) options.security = sec;
  options.sender = args.sender.empty() ? default_sender() : args.sender;
  if (args.insecure) {
    spdlog::warn("*****************************************************************************");
    spdlog::warn("--insecure: sending WITHOUT DDS Security: no identity, no permissions, nothing");
    spdlog::warn("encrypted. A crane running `sim --input dds` accepts only authenticated,");
    spdlog::warn("permitted operators: this run only shows that it ignores these commands.");
    spdlog::warn("*****************************************************************************");
  }

  std::unique_ptr<dds::CommandWriter> writer;
  try {
    writer = std::make_unique<dds::CommandWriter>(options);
  } catch (const std::invalid_argument& e) {
    spdlog::error("{}", e.what());
    return kExitUsage;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }

  try {
    g_stop.store(false);
    std::unique_ptr<input::KeyboardSource> keyboard;
    if (!replay) {
      input::JoystickMapping mapping = jcfg.mapping;
      mapping.frame = input::MappingFrame::kCartesian;  // the console does not know the tip
      mapping.slew = input::SlewMode::kTangential;
      keyboard = std::make_unique<input::KeyboardSource>(0, mapping, jcfg.keyboard, &g_stop);
      std::set_terminate([] {
        input::KeyboardSource::restore_terminal();
        std::abort();
      });
    }
    struct sigaction sa = {};
    sa.sa_handler = on_remote_stop_signal;
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);

    spdlog::info("remote: {} as '{}' on DDS domain {}{} at {:g} Hz",
                 replay ? std::string(replay->source_name()) : std::string("keyboard"),
                 options.sender, options.domain_id,
                 args.insecure ? " WITHOUT DDS Security" : " with DDS Security", args.rate_hz);
    if (keyboard) print_keys();
    const bool draw = keyboard && isatty(1) != 0;

    std::optional<input::ReplayCursor> cursor;
    if (replay) cursor.emplace(*replay);
    const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(1.0 / args.rate_hz));
    const double start = input::steady_now_s();
    auto next = std::chrono::steady_clock::now();
    double matched_since = -1.0;
    double play_start = -1.0;
    bool played = false;
    const Eigen::Vector3d no_tip =
        Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    while (!g_stop.load()) {
      const double now = input::steady_now_s() - start;
      if (args.duration_s > 0.0 && now >= args.duration_s) break;
      const int matched = writer->matched_readers();
      if (matched > 0 && matched_since < 0.0) matched_since = now;
      std::array<double, 3> v{0.0, 0.0, 0.0};
      bool deadman = false;
      if (replay) {
        if (play_start < 0.0 &&
            ((matched_since >= 0.0 && now - matched_since >= kLeadIn_s) || now >= args.wait_s)) {
          play_start = now;
          if (matched_since < 0.0) {
            spdlog::warn("no crane's reader matched within {:g} s: playing the replay anyway",
                         args.wait_s);
          }
        }
        if (play_start >= 0.0) {
          const double t = now - play_start;
          if (t > replay->end_time_s()) {
            played = true;
            break;
          }
          const Eigen::Vector3d c = cursor->command_at(t);
          if (c.allFinite()) {  // else a stop row: the deadman released, zero
            v = {c.x(), c.y(), c.z()};
            deadman = true;
          }
        }
      } else {
        keyboard->begin_cycle(input::steady_now_s(), no_tip);
        input::OperatorCommand c;
        if (keyboard->poll(c) == input::SourceState::kDisconnected) break;
        if (c.v_m_s.allFinite()) v = {c.v_m_s.x(), c.v_m_s.y(), c.v_m_s.z()};
        deadman = c.deadman;
      }
      writer->write(v, deadman);
      if (draw) {
        std::printf(
            "\r\033[Kt %6.1f s | sent %llu | crane %s | deadman %s | speed %d/%d | v %5.2f %5.2f "
            "%5.2f m/s",
            now, static_cast<unsigned long long>(writer->stats().samples_written),
            matched > 0 ? "matched" : "NOT matched", deadman ? "ON " : "off",
            keyboard->speed_step(), input::KeyboardState::kSteps, v[0], v[1], v[2]);
        std::fflush(stdout);
      }
      next += period;
      std::this_thread::sleep_until(next);
    }
    for (int i = 0; i < kTailSamples; ++i) {
      writer->write({0.0, 0.0, 0.0}, false);
      std::this_thread::sleep_for(period);
    }
    const double elapsed = input::steady_now_s() - start;
    keyboard.reset();  // restores the terminal
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    if (draw) std::printf("\n");

    const dds::CommandWriterStats s = writer->stats();
    std::printf("craneassist remote: %s as '%s', DDS domain %d\n",
                replay ? std::string(replay->source_name()).c_str() : "keyboard",
                options.sender.c_str(), options.domain_id);
    if (args.insecure) {
      std::printf("  DDS Security: NONE (--insecure): no identity, nothing encrypted\n");
    } else {
      std::printf("  DDS Security: identity %s, permissions %s\n", sec.identity_certificate.c_str(),
                  sec.permissions.c_str());
    }
    std::printf(
        "  sent %llu samples in %.2f s at %g Hz (%llu write errors)%s\n",
        static_cast<unsigned long long>(s.samples_written), elapsed, args.rate_hz,
        static_cast<unsigned long long>(s.write_errors),
        replay ? (played ? ", replay played to its end" : ", replay NOT played to its end") : "");
    if (s.first_match_s >= 0.0) {
      std::printf("  crane reader matched: yes, %.2f s after start (peak %d readers)\n",
                  s.first_match_s, s.peak_matched_readers);
    } else {
      std::printf("  crane reader matched: no (no crane accepted this participant%s)\n",
                  args.insecure ? ": as expected without DDS Security" : "");
    }
  } catch (const std::exception& e) {
    input::KeyboardSource::restore_terminal();
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace craneassist::cli
