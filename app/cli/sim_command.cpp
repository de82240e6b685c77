#include "sim_command.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <exception>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <utility>

#include "crane_options.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/config/joystick_config.hpp"
#include "craneassist/control/live_loop.hpp"
#include "craneassist/input/evdev_source.hpp"
#include "craneassist/input/goal_source.hpp"
#include "craneassist/input/keyboard_source.hpp"
#include "craneassist/input/replay_source.hpp"
#include "craneassist/input/sdl_source.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/valves/reference_follower.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"
#include "remote_input.hpp"
#include "replay_command.hpp"
#include "research/goal_move.hpp"

namespace craneassist::cli {
namespace {

std::atomic<bool> g_stop{false};

extern "C" void on_stop_signal(int) {
  g_stop.store(true);
  input::KeyboardSource::restore_terminal();  // at once, in case the loop takes a while to stop
}

// The status line and the device event messages, from the loop's status board (UI thread).
class StatusReporter {
 public:
  // remote: the DDS input's sender and events (empty functions: another input).
  StatusReporter(const control::LiveStatusBoard& board, const input::KeyboardSource* keyboard,
                 const RemoteInput& remote)
      : board_(board), keyboard_(keyboard), remote_(remote), draw_(isatty(1) != 0) {}

  void run(const std::atomic<bool>& done) {
    while (!done.load()) {
      report(board_.read());
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    report(board_.read());
    if (draw_) std::printf("\n");
    std::fflush(stdout);
  }

 private:
  void clear_line() {
    if (draw_) std::printf("\r\033[K");
  }

  void report(const control::LiveStatus& s) {
    if (s.disconnects > disconnects_) {
      clear_line();
      spdlog::warn("t {:.2f} s: input device disconnected: stopping", s.t);
    }
    if (s.reconnects > reconnects_) {
      clear_line();
      spdlog::info("t {:.2f} s: input device attached again (release and press the deadman)", s.t);
    }
    disconnects_ = s.disconnects;
    reconnects_ = s.reconnects;
    if (s.fault != fault_) {
      if (s.fault == input::InputFault::kDisconnected && s.disconnects == 0) {
        clear_line();
        spdlog::info("waiting for the input device (plug it in; then press the deadman)");
      } else if (s.fault == input::InputFault::kStale) {
        clear_line();
        spdlog::warn("t {:.2f} s: input stale {:.0f} ms: stopping", s.t, s.input_age_s * 1e3);
      } else if (s.fault == input::InputFault::kNotFinite ||
                 s.fault == input::InputFault::kOutOfRange) {
        clear_line();
        spdlog::warn("t {:.2f} s: {}: stopping", s.t, input::to_string(s.fault));
      }
      fault_ = s.fault;
    }
    char sender[64] = "";
    if (remote_.sender) {  // the remote operator (OperatorCommand.sender)
      const std::string now_sender = remote_.sender();
      const RemoteInputEvents events = remote_.events ? remote_.events() : RemoteInputEvents{};
      if (now_sender != sender_) {
        clear_line();
        spdlog::info("remote operator: '{}' (DDS)", now_sender);
        sender_ = now_sender;
      }
      if (events.operator_changes > operator_changes_) {
        if (operator_changes_ > 0) {
          clear_line();
          spdlog::warn(
              "t {:.2f} s: dds input: another writer took the command over ('{}'); its commands "
              "pass once it has released and pressed the deadman",
              s.t, now_sender);
        }
        operator_changes_ = events.operator_changes;
      }
      // Dropped samples, at most one message a second.
      if ((events.malformed > malformed_ || events.replayed > replayed_) &&
          s.t - dropped_reported_t_ >= 1.0) {
        clear_line();
        spdlog::warn(
            "t {:.2f} s: dds input: {} malformed, {} replayed samples dropped so far (they count "
            "as missing)",
            s.t, events.malformed, events.replayed);
        malformed_ = events.malformed;
        replayed_ = events.replayed;
        dropped_reported_t_ = s.t;
      }
      std::snprintf(sender, sizeof sender, " | from %.40s", sender_.c_str());
    }
    if (!draw_) return;
    char speed_step[32] = "";
    if (keyboard_ != nullptr) {
      std::snprintf(speed_step, sizeof speed_step, " | speed %d/%d%s", keyboard_->speed_step(),
                    input::KeyboardState::kSteps, keyboard_->latched() ? " latched" : "");
    }
    char age[32] = "";
    if (s.fault == input::InputFault::kStale) {
      std::snprintf(age, sizeof age, " %.0f ms", s.input_age_s * 1e3);
    }
    char base[96] = "";
    if (s.base.present) {  // the wheeled base (sim --drive): pose, speed, share of Q_max
      std::snprintf(base, sizeof base, " | base x %6.2f y %6.2f %4.0f deg %5.2f m/s Q %3.0f%%",
                    s.base.x_m, s.base.y_m, s.base.phi_rad * 180.0 / 3.14159265358979, s.base.v_m_s,
                    100.0 * s.base.motor_flow_sum_m3_s / s.base.drive_max_flow_m3_s);
    }
    std::printf(
        "\r\033[Kt %6.1f s | %-8s | deadman %s%s%s | tip x %5.2f y %5.2f z %5.2f m | %.2f m/s%s | "
        "%s%s",
        s.t, s.status, s.deadman ? "ON " : "off", speed_step, sender, s.tip.x(), s.tip.y(),
        s.tip.z(), s.tip_v.norm(), base, s.stop_reason, age);
    std::fflush(stdout);
  }

  const control::LiveStatusBoard& board_;
  const input::KeyboardSource* keyboard_;
  const RemoteInput& remote_;
  std::string sender_;
  bool draw_;
  int disconnects_ = 0, reconnects_ = 0;
  std::uint64_t malformed_ = 0, replayed_ = 0;
  int operator_changes_ = 0;
  double dropped_reported_t_ = -1e9;
  input::InputFault fault_ = input::InputFault::kNone;
};

void print_keys(bool drive) {
  std::printf(
      "keys: space deadman on/off | w/s or up/down reach | a/d or left/right slew | r/f or "
      "PgUp/PgDn height | +/- speed | l latch | x stop axes | q quit\n");
  if (drive) std::printf("drive: i/k forward/back | u/o steer left/right\n");
}

}  // namespace

CLI::App* add_sim_command(CLI::App& cli, SimArgs& args) {
  auto* sim = cli.add_subcommand(
      "sim",
      "Drive the crane live: keyboard, joystick (evdev, SDL), a remote operator over DDS "
      "Security or a replay file; the simulated crane, or with --backend can the machine on the "
      "CAN bus");
  add_config_option(*sim, args.config_file);
  sim->add_option("--input", args.input,
                  "keyboard (default on a terminal), evdev, sdl, dds (a remote operator, "
                  "docs/remote-commands.md), web (the virtual joystick of --web; its default), "
                  "goal (move the tip to --goal energy-optimally; docs/mhsb.md) or replay FILE")
      ->expected(1, 2);
  sim->add_option("--joystick", args.joystick_file,
                  "Joystick mapping YAML (docs/joystick.md; default: the embedded "
                  "config/joysticks/gamepad.yaml, web.yaml for --input web; with --drive "
                  "gamepad_drive.yaml, web_drive.yaml)")
      ->check(CLI::ExistingFile);
  sim->add_option("--device", args.device, "evdev: the device, e.g. /dev/input/event5");
  sim->add_option(
         "--duration", args.duration_s,
         "Seconds to run (default: until q, Ctrl-C or SIGTERM; a replay: its length + 1 s)")
      ->check(FiniteRange(0.01, 1e6));
  sim->add_option("--log", args.log_file, "Per-cycle CSV log (docs/log-format.md)");
  sim->add_option("--record", args.record_file,
                  "Record the command the controller got, in the replay format");
  sim->add_flag("--no-realtime", args.no_realtime,
                "--input replay only: run as fast as possible on machine time");
  sim->add_flag("--rt", args.rt,
                "Real-time loop thread: lock memory and SCHED_FIFO priority 80 (docs/realtime.md)");
  sim->add_flag("--lock-memory", args.lock_memory, "Lock the process's memory (mlockall)");
  sim->add_option("--rt-priority", args.rt_priority,
                  "SCHED_FIFO priority of the loop thread, 1..99 (0: the normal scheduler)")
      ->check(CLI::Range(0, 99));
  sim->add_option("--cpu", args.cpu, "Pin the loop thread to this core")
      ->check(CLI::Range(0, 1023));
  sim->add_option("--goal", args.goal,
                  "--input goal: the tip's goal X,Z in m in the arm's vertical plane (X out from "
                  "the slew axis, Z up), planned at the start");
  sim->add_option("--goal-at", args.goal_at,
                  "--input goal: T:X,Z, a new goal T s after the start (repeatable); goals typed "
                  "as X,Z lines on standard input replan too");
  sim->add_option("--goal-weights", args.goal_weights,
                  "--input goal: the planner's weights w1,w2,w3 of energy, time and mode switches "
                  "(default 1,0,0: energy-optimal)");
  sim->add_option("--goal-grid", args.goal_grid,
                  "--input goal: the planner's grid spacing, e.g. \"0.25 m\" (default: reach / "
                  "40)");
  sim->add_option("--goal-speed", args.goal_speed_m_s,
                  "--input goal: the fastest tip speed a planned move asks for, m/s (default 0.5)")
      ->check(FiniteRange(0.01, 10.0));
  sim->add_option("--goal-table", args.goal_table,
                  "--input goal: the posture table file (default: the cache, as ptp)");
  add_payload_option(*sim, args.payload_kg);
  add_sway_option(*sim, args.no_sway_damping);
  sim->add_flag("--payload-known", args.payload_known,
                "Tell the controller the payload instead of letting the crane scale estimate it "
                "(docs/loads.md)");
  add_initial_option(*sim, args.initial);
  add_resolution_option(*sim, args.resolution, "for the run");
  add_backend_options(*sim, args.machine);
  sim->add_flag("--drive", args.drive,
                "Drive mode: the crane on the simulated wheeled base of docs/mobile.md, one stick "
                "(or the keys i/k u/o) driving it, flow-bounded, while the other moves the tip");
  sim->add_option("--base", args.base_file,
                  "Base config YAML for --drive (implies it; default: the embedded "
                  "config/machines/mobile_base.yaml)")
      ->check(CLI::ExistingFile);
  sim->add_option("--pump", args.pump,
                  "--drive: shared (one pump of the drive's Q_max for the motors and the crane, "
                  "the drive first) or separate (default: the base config's)")
      ->check(CLI::IsMember({"shared", "separate"}));
  add_telemetry_options(*sim, args.telemetry, true);
  add_foxglove_options(*sim, args.foxglove);
  add_web_options(*sim, args.web);
  return sim;
}

int run_sim_command(const SimArgs& args) {
  std::string kind = !args.input.empty() ? args.input[0] : args.web.on ? "web" : "keyboard";
  if (kind != "keyboard" && kind != "evdev" && kind != "sdl" && kind != "dds" && kind != "replay" &&
      kind != "web" && kind != "goal") {
    spdlog::error(
        "--input: unknown input '{}' (expected keyboard, evdev, sdl, dds, web, goal or replay "
        "FILE)",
        kind);
    return kExitUsage;
  }
  const bool goal_options = !args.goal.empty() || !args.goal_at.empty();
  if (kind == "goal" && !goal_options) {
    spdlog::error("--input goal needs --goal X,Z or --goal-at T:X,Z");
    return kExitUsage;
  }
  if (kind != "goal" && goal_options) {
    spdlog::error("--goal, --goal-at: only with --input goal");
    return kExitUsage;
  }
  const bool web_on = args.web.on || kind == "web";
  if (web_on && args.no_realtime) {
    spdlog::error("--web: the web view runs in real time (leave out --no-realtime)");
    return kExitUsage;
  }
  if (kind == "dds" && !remote_input_available()) {
    spdlog::error("--input dds: this craneassist was built without DDS (CRANEASSIST_DDS=OFF)");
    return kExitUsage;
  }
  if ((kind == "replay") != (args.input.size() == 2)) {
    spdlog::error(kind == "replay" ? "--input replay needs a FILE"
                                   : "--input: only replay takes a FILE");
    return kExitUsage;
  }
  if (args.no_realtime && kind != "replay") {
    spdlog::error("--no-realtime works with --input replay only (devices run in real time)");
    return kExitUsage;
  }
  if (kind == "keyboard" && !isatty(0)) {
    spdlog::error(
        "--input keyboard needs a terminal on stdin (give --input evdev, sdl or replay FILE)");
    return kExitUsage;
  }
  const bool drive = args.drive || !args.base_file.empty();
  if (!args.pump.empty() && !drive) {
    spdlog::error("--pump: only with --drive (the wheeled base)");
    return kExitUsage;
  }
  const bool pad = kind == "evdev" || kind == "sdl";  // a gamepad (not the page, not keys)
  std::optional<config::BaseConfig> base;
  config::CraneConfig cfg;
  config::JoystickConfig jcfg;
  config::TelemetryConfig tcfg;
  std::optional<input::Replay> replay;
  MachineInputs machine_inputs;
  try {
    cfg = load_crane(args.config_file);
    apply_crane_options(cfg, {args.payload_kg, args.initial, args.resolution,
                              !uses_can_backend(args.machine, cfg), args.no_sway_damping});
    // In the drive mode a pad's and the page's right stick drive the base (a mapping with a
    // drive stick); the keyboard has its own drive keys.
    jcfg = !args.joystick_file.empty() ? config::load_joystick_config(args.joystick_file)
           : kind == "web" && drive    ? config::web_drive_joystick_config()
           : kind == "web"             ? config::web_joystick_config()
           : pad && drive              ? config::drive_joystick_config()
                                       : config::default_joystick_config();
    if (kind == "replay") {
      replay = input::Replay::load_file(args.input[1]);
      if (replay->has_waits()) {
        spdlog::warn(
            "{}: its wait rows are played at their times here (live input does not wait); "
            "craneassist replay waits for the grapple to settle (docs/replay-format.md#waits)",
            args.input[1]);
      }
    }
    tcfg = load_telemetry_settings(args.telemetry);
    if (kind == "dds") check_remote_input_settings(tcfg);
    apply_backend_options(cfg, args.machine);
    machine_inputs = load_machine_inputs(cfg, args.machine);
    if (drive) {
      base = config::load_base_or_default(args.base_file);
      if (!args.pump.empty()) base->shared_with_crane = args.pump == "shared";
    }
  } catch (...) {
    return input_error_exit("replay");
  }

  if (args.no_realtime && uses_can_backend(args.machine, cfg)) {
    spdlog::error("--no-realtime: the can backend always runs in real time");
    return kExitUsage;
  }

  // --input goal: the planner, its posture table (cached) and the goals, before anything moves.
  std::unique_ptr<input::GoalPlanning> goal_move;
  if (kind == "goal") {
    goal_move = make_goal_move(cfg, GoalMoveOptions{.goal = args.goal,
                                                    .goal_at = args.goal_at,
                                                    .weights = args.goal_weights,
                                                    .grid = args.goal_grid,
                                                    .table = args.goal_table,
                                                    .speed_m_s = args.goal_speed_m_s});
  }

  try {
    Machine machines;
    if (const int rc = machines.open(cfg, args.machine, machine_inputs, base ? &*base : nullptr);
        rc != kExitOk) {
      return rc;
    }
    valves::MachineInterface& machine = machines.get();
    g_stop.store(false);
    std::unique_ptr<input::CommandSource> source;
    input::KeyboardSource* keyboard = nullptr;
    input::GoalSource* goal_source = nullptr;
    RemoteInput remote;
    if (kind == "dds") {
      remote = open_remote_input(tcfg, jcfg.monitor.stale_timeout_s);
      source = std::move(remote.source);
      spdlog::info(
          "dds input: craneassist/operator_command on DDS domain {} with DDS Security "
          "({}); waiting for an operator (craneassist remote)",
          tcfg.domain_id, tcfg.source_name);
    } else if (kind == "keyboard") {
      auto kb = std::make_unique<input::KeyboardSource>(0, jcfg.mapping, jcfg.keyboard, &g_stop);
      keyboard = kb.get();
      source = std::move(kb);
    } else if (kind == "evdev") {
      const std::string path = args.device.empty() ? jcfg.mapping.device_path : args.device;
      source = std::make_unique<input::EvdevSource>(
          jcfg.mapping, input::libevdev_opener(path, jcfg.mapping.device_name),
          input::EvdevSource::Options{});
    } else if (kind == "sdl") {
      source = std::make_unique<input::SdlSource>(jcfg.mapping, input::SdlSource::Options{});
    } else if (kind == "replay") {
      source = std::make_unique<input::ReplaySource>(*replay);
    } else if (kind == "goal") {
      auto goal = std::make_unique<input::GoalSource>(
          input::GoalSourceSettings{.arming_s = jcfg.monitor.deadman_hold_s});
      goal_source = goal.get();
      source = std::move(goal);
    }  // web: the page's joystick, once the server runs (below)
    std::set_terminate([] {
      input::KeyboardSource::restore_terminal();
      std::abort();
    });
    struct sigaction sa = {};
    sa.sa_handler = on_stop_signal;
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);

    WebView web;
    if (web_on) {
      if (const int rc = web.open(args.web, cfg, true, base ? &base->model : nullptr);
          rc != kExitOk) {
        return rc;
      }
      if (kind == "web") source = web.pad_source(jcfg.mapping);
    }
    Telemetry telemetry;
    if (const int rc = telemetry.open(tcfg, !args.telemetry.off, cfg, machine.name());
        rc != kExitOk) {
      return rc;
    }
    std::optional<control::CsvLog> log;
    if (!args.log_file.empty()) {
      log.emplace(args.log_file, cfg.model.dof(), std::size_t{1} << 14, base.has_value());
    }
    std::vector<input::ReplayRow> record;
    control::LiveStatusBoard board;
    control::LiveOptions options;
    options.monitor = jcfg.monitor;
    options.controller.payload_known = args.payload_known;
    if (base) options.base = &base->model;
    options.realtime = !args.no_realtime;  // always on the can backend (checked above)
    options.duration_s = args.duration_s > 0.0 ? args.duration_s
                         : replay              ? replay->end_time_s() + 1.0
                                               : 0.0;
    options.stop = &g_stop;
    options.status_board = &board;
    options.realtime_setup.lock_memory = args.rt || args.lock_memory;
    options.realtime_setup.priority = args.rt_priority > 0 ? args.rt_priority : args.rt ? 80 : 0;
    options.realtime_setup.cpu = args.cpu;
    if (control::CycleObserver* o = telemetry.observer()) options.observers.push_back(o);
    if (control::CycleObserver* o = web.observer()) options.observers.push_back(o);
    FoxgloveOutputs foxglove;
    if (const int rc = foxglove.open(args.foxglove, cfg, base.has_value(), options.realtime);
        rc != kExitOk) {
      return rc;
    }
    foxglove.add_observers(options.observers);
    if (!args.record_file.empty()) {
      options.record = &record;
      if (options.duration_s > 0.0) {
        options.record_capacity =
            static_cast<std::size_t>(options.duration_s * cfg.control.rate_hz) + 16;
      }
    }
    spdlog::info("sim: {} input ({}) on {} with the {} backend, resolution {}{}", source->name(),
                 jcfg.source_name, cfg.model.name, machine.name(),
                 config::resolution_description(cfg),
                 options.realtime ? ", real time" : ", as fast as possible");
    if (keyboard != nullptr) print_keys(drive);
    if (base) {
      if ((pad || kind == "web") &&
          !(jcfg.mapping.drive[0].enabled || jcfg.mapping.drive[1].enabled)) {
        spdlog::warn(
            "--drive: the joystick mapping ({}) has no drive stick (joystick.drive): the base "
            "does not move; config/joysticks/gamepad_drive.yaml and web_drive.yaml have one",
            jcfg.source_name);
      }
      spdlog::info("drive: {} ({}), {}; the crane's tip in the world includes the base's pose",
                   base->model.name.empty() ? "wheeled base" : base->model.name, base->source_name,
                   base->shared_with_crane ? "one pump for the drive and the crane"
                                           : "the crane on its own pump");
    }

    if (goal_source != nullptr) goal_move->start(*goal_source);
    std::atomic<bool> done{false};
    StatusReporter reporter(board, keyboard, remote);
    std::thread ui([&] { reporter.run(done); });
    control::LiveSummary s;
    try {
      s = control::run_live(cfg, *source, machine, options, log ? &*log : nullptr);
    } catch (...) {
      done.store(true);
      ui.join();
      if (goal_move) goal_move->stop();
      throw;
    }
    if (goal_move) goal_move->stop();
    // Every valve to its safe state at once (Machine::finish() below deactivates and reports).
    machine.safe_stop();
    done.store(true);
    ui.join();
    const std::string remote_report = remote.report ? remote.report() : std::string();
    // The goal input's last state (a static string) before the source goes.
    const char* goal_state = goal_source != nullptr ? goal_source->state() : "";
    goal_source = nullptr;
    source.reset();  // restores the terminal; ends the DDS input
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);

    if (!args.record_file.empty()) {
      std::ofstream out(args.record_file, std::ios::binary);
      if (!out) throw std::runtime_error(args.record_file + ": cannot open for writing");
      input::write_replay(out, record);
      if (!out) throw std::runtime_error(args.record_file + ": write failed");
    }
    std::printf("craneassist sim: %s input on %s, %s backend\n", kind.c_str(),
                cfg.model.name.c_str(), machine.name());
    std::printf("  ran %.2f s of machine time in %.2f s, %ld cycles, latest cycle start %.1f ms\n",
                s.duration_s, s.wall_time_s, s.cycles, s.max_late_s * 1e3);
    std::printf("  tip: path %.2f m, peak speed %.2f m/s; operator command passed in %ld cycles\n",
                s.tip_path_m, s.peak_tip_speed_m_s, s.enabled_cycles);
    std::printf("  cycle timing: %s\n", control::describe(s.timing).c_str());
    print_load_line(s.load, args.payload_known, !cfg.load_chart.empty());
    print_swing_line(s.swing, cfg);
    print_stop_lines(s.stop, s.end_stop,
                     s.stop_cycles > 0 ? static_cast<double>(s.stop_cycles) / cfg.control.rate_hz
                                       : s.stop.time_s,
                     s.peak_spool_step,
                     valves::max_spool_step(cfg.model.valves, 1.0 / cfg.control.rate_hz));
    if (options.realtime_setup.lock_memory || options.realtime_setup.priority > 0 ||
        options.realtime_setup.cpu >= 0) {
      const control::RealtimeResult& r = s.realtime_result;
      std::printf("  real time: memory %s, %s, %s\n", r.memory_locked ? "locked" : "not locked",
                  r.priority > 0 ? ("SCHED_FIFO " + std::to_string(r.priority)).c_str()
                                 : "normal scheduler",
                  r.cpu >= 0 ? ("core " + std::to_string(r.cpu)).c_str() : "any core");
      if (!r.refused.empty()) spdlog::warn("real time: {}", r.refused);
    }
    std::printf("  input device: %d disconnects, %d re-attaches\n", s.disconnects, s.reconnects);
    if (goal_move) {
      for (const std::string& line : goal_move->report()) std::printf("  %s\n", line.c_str());
      std::printf("  goal input at the end: %s\n", goal_state);
    }
    if (base) {
      const valves::BaseMeasurement b = board.read().base;
      std::printf("  base: at x %.2f m, y %.2f m, heading %.1f deg; %s\n", b.x_m, b.y_m,
                  b.phi_rad * 180.0 / 3.14159265358979,
                  b.shared_pump ? "one pump for the drive and the crane" : "separate pumps");
    }
    if (!remote_report.empty()) std::printf("%s\n", remote_report.c_str());
    if (const std::string r = web.report(); !r.empty()) std::printf("%s\n", r.c_str());
    if (log) std::printf("  log: %s (%zu rows)\n", log->path().c_str(), log->rows_written());
    if (!args.record_file.empty()) {
      std::printf("  record: %s (%zu rows%s)\n", args.record_file.c_str(), record.size(),
                  s.record_rows_dropped > 0 ? ", SOME DROPPED" : "");
    }
    telemetry.finish();
    if (const int rc = foxglove.finish(); rc != kExitOk) return rc;
    if (s.log_rows_dropped > 0) spdlog::warn("{} log rows dropped", s.log_rows_dropped);
    if (s.machine_fault) spdlog::error("the machine reported a fault: run stopped");
    if (const int rc = machines.finish(); rc != kExitOk) return rc;
  } catch (const std::exception& e) {
    input::KeyboardSource::restore_terminal();
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace craneassist::cli
