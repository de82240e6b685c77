#include "can_commands.hpp"

#include <spdlog/spdlog.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <optional>
#include <vector>

#include "crane_options.hpp"
#include "craneassist/can/heartbeat.hpp"
#include "craneassist/can/valve_frames.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"
#include "embedded_replays.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"

namespace craneassist::cli {

can::CanMapping load_mapping_or_default(const std::string& file) {
  if (file.empty()) {
    return can::parse_can_mapping(cli::embedded::kK70mCanMappingYaml,
                                  "<embedded config/can/k70m_can.yaml>");
  }
  return can::load_can_mapping(file);
}

CanMachine::CanMachine(const dynamics::CraneModel& model, const std::string& iface,
                       const can::CanMapping& mapping, const std::string& candump_log,
                       double feedback_timeout_s) {
  transport_ = std::make_unique<can::SocketCanTransport>(iface);
  can::CanBackendOptions options;
  options.candump_log = candump_log;
  options.feedback_timeout_s = feedback_timeout_s;
  backend_ = std::make_unique<can::CanBackend>(mapping, model, *transport_, options);
}

void CanMachine::report() const {
  const auto c = backend_->counters();
  std::printf(
      "  CAN %s: sent %llu, received %llu, unknown %llu, bad %llu, unsupported %llu, bus errors "
      "%llu, send queue full %llu, send errors %llu, watchdog block frames %llu, heartbeats %llu, "
      "log dropped %llu, address claim frames %llu, valve replies %llu, DM1 %llu\n",
      "counters", static_cast<unsigned long long>(c.frames_sent),
      static_cast<unsigned long long>(c.frames_received),
      static_cast<unsigned long long>(c.unknown_frames),
      static_cast<unsigned long long>(c.bad_frames),
      static_cast<unsigned long long>(c.unsupported_frames),
      static_cast<unsigned long long>(c.bus_error_frames),
      static_cast<unsigned long long>(c.send_queue_full),
      static_cast<unsigned long long>(c.send_errors),
      static_cast<unsigned long long>(c.watchdog_block_frames),
      static_cast<unsigned long long>(c.heartbeats_sent),
      static_cast<unsigned long long>(c.log_dropped),
      static_cast<unsigned long long>(c.claim_frames_sent),
      static_cast<unsigned long long>(c.valve_replies),
      static_cast<unsigned long long>(c.dm1_messages));
  if (backend_->faulted()) {
    std::printf("  CAN FAULT (%s) at %.3f s: %s\n", can::to_string(backend_->fault_reason()),
                backend_->fault_time_s(), backend_->fault_text().c_str());
    std::printf(
        "  every valve section was commanded to block and held there; the fault is latched: "
        "recovery needs a deliberate re-enable (check the machine and the bus, then start "
        "craneassist again)\n");
  }
}

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) {
  g_stop.store(true);
}

std::int64_t mono_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

// The feedback frames the emulated machine sends: one per distinct identifier, each signal of
// the mapping (positions, pressures) written into its frame.
struct FeedbackSignal {
  std::size_t frame = 0;
  int joint = 0;
  // 0 position, 1 pressure a, 2 pressure b, 3 pump pressure, 4 pump flow, 5 and 6 the grapple's
  // swing towards and across the reach
  int kind = 0;
  const can::SignalSpec* spec = nullptr;
};

}  // namespace

CLI::App* add_emulate_command(CLI::App& cli, EmulateArgs& args) {
  auto* cmd = cli.add_subcommand(
      "emulate",
      "Run the simulated crane behind the CAN protocol: decode valve command frames, step the "
      "simulator in real time, send joint position and pressure frames (and, when the mapping "
      "asks, the valves' replies and DM1)");
  cmd->add_option("--can", args.iface, "CAN interface, e.g. vcan0 or can0")->required();
  add_config_option(*cmd, args.config_file);
  add_payload_option(*cmd, args.payload_kg);
  cmd->add_option("--mapping", args.mapping_file,
                  "CAN mapping YAML (default: the embedded config/can/k70m_can.yaml)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--lag-warning", args.lag_warning_s,
                  "Say so (at most once a second) when the simulation falls this many seconds "
                  "behind the wall clock")
      ->check(FiniteRange(0.001, 10.0))
      ->capture_default_str();
  cmd->add_option("--feedback-period", args.feedback_period_s, "Seconds between feedback frames")
      ->check(FiniteRange(0.001, 1.0))
      ->capture_default_str();
  cmd->add_option("--duration", args.duration_s, "Seconds to run (default: until killed)")
      ->check(FiniteRange(0.0, 1e6));
  // Test hooks of the can_vm test (seconds since the emulator started).
  cmd->add_option("--test-valve-fault-at", args.faults.valve_fault_at_s)
      ->check(FiniteRange(0.0, 1e6))
      ->group("");
  cmd->add_option("--test-valve-fault-joint", args.faults.valve_fault_joint)->group("");
  cmd->add_option("--test-reply-stop-at", args.faults.reply_stop_at_s)
      ->check(FiniteRange(0.0, 1e6))
      ->group("");
  cmd->add_option("--test-dm1-fault-at", args.faults.dm1_fault_at_s)
      ->check(FiniteRange(0.0, 1e6))
      ->group("");
  return cmd;
}

int run_emulate_command(const EmulateArgs& args) {
  config::CraneConfig cfg;
  can::CanMapping mapping;
  std::optional<EmulatedNodes> nodes;
  try {
    cfg = load_crane(args.config_file);
    apply_crane_options(cfg, {.payload_kg = args.payload_kg});
    mapping = load_mapping_or_default(args.mapping_file);
    can::check_mapping_fits(mapping, cfg.model);  // before the bus is opened
    nodes.emplace(mapping, args.faults);
  } catch (const std::exception& e) {
    spdlog::error("config: {}", e.what());
    return kExitUsage;
  }
  const int n = cfg.model.dof();
  try {
    can::SocketCanTransport bus(args.iface);
    sim_backend::SimBackend sim(cfg.model, offline::sim_settings(cfg));
    std::vector<can::CanFrame> frames;
    std::vector<FeedbackSignal> signals;
    auto add = [&](int joint, int kind, const can::SignalSpec& spec) {
      std::size_t f = 0;
      while (f < frames.size() &&
             !(frames[f].id == spec.id && frames[f].extended == spec.extended)) {
        ++f;
      }
      if (f == frames.size()) {
        can::CanFrame fr;
        fr.id = spec.id;
        fr.extended = spec.extended;
        frames.push_back(fr);
      }
      frames[f].dlc = std::max(frames[f].dlc, can::required_dlc(spec));
      signals.push_back({f, joint, kind, &spec});
    };
    for (int j = 0; j < n; ++j) {
      const auto& jm = mapping.joints[static_cast<std::size_t>(j)];
      add(j, 0, jm.position);
      if (jm.pressure_a) add(j, 1, *jm.pressure_a);
      if (jm.pressure_b) add(j, 2, *jm.pressure_b);
    }
    if (mapping.pump.pressure) add(0, 3, *mapping.pump.pressure);
    if (mapping.pump.flow) add(0, 4, *mapping.pump.flow);
    if (mapping.grapple.swing_radial) add(0, 5, *mapping.grapple.swing_radial);
    if (mapping.grapple.swing_tangential) add(0, 6, *mapping.grapple.swing_tangential);
    std::vector<char> unmeasured(frames.size(), 0);  // a frame with a signal the sim lacks
    std::signal(SIGTERM, on_signal);
    std::signal(SIGINT, on_signal);

    valves::ValveCommand command;
    command.spool = dynamics::JointVector::Zero(n);
    std::vector<std::int64_t> last_command_ns(static_cast<std::size_t>(n), 0);
    valves::MachineState state;
    can::Received rx;
    std::optional<can::HeartbeatMonitor> heartbeat;
    if (mapping.heartbeat) heartbeat.emplace(*mapping.heartbeat);
    bool heartbeat_ok = false;
    unsigned long long commands = 0, bad = 0, other = 0, sent = 0, send_failed = 0, behind = 0,
                       network = 0;
    const double step = cfg.simulation.step_s;
    const auto step_ns = static_cast<std::int64_t>(std::llround(step * 1e9));
    const auto feedback_ns = static_cast<std::int64_t>(std::llround(args.feedback_period_s * 1e9));
    const auto command_timeout_ns = static_cast<std::int64_t>(args.command_timeout_s * 1e9);
    const std::int64_t start = mono_ns();
    std::int64_t sim_ns = 0;  // simulated time, locked to the wall clock
    std::int64_t next_feedback = 0;
    // Lag: how far the simulated time trails the wall clock after stepping. Up to 100 steps are
    // taken per pass; a simulation slower than real time trails more and more, and beyond that it
    // jumps ahead (counted as "fell behind"). Either way the machine the controller drives runs
    // slow or stutters, so it is said while it happens, not only at the end.
    const auto lag_warning_ns = static_cast<std::int64_t>(args.lag_warning_s * 1e9);
    std::int64_t max_lag_ns = 0, lagging_ns = 0, last_lag_report = -1000000000;
    std::printf(
        "craneassist emulate: %s on %s, mapping %s, payload %.0f kg, feedback every %.0f ms\n",
        cfg.model.name.c_str(), args.iface.c_str(), mapping.source.c_str(),
        dynamics::payload_mass_kg(cfg.model), args.feedback_period_s * 1e3);
    std::fflush(stdout);
    while (!g_stop.load()) {
      const std::int64_t now = mono_ns() - start;
      if (args.duration_s > 0.0 && now > static_cast<std::int64_t>(args.duration_s * 1e9)) break;
      for (int k = 0; k < 256; ++k) {
        bus.receive(rx);
        if (rx.kind == can::ReceiveKind::kNone) break;
        if (rx.kind != can::ReceiveKind::kFrame) {
          ++other;
          continue;
        }
        if (heartbeat && heartbeat->on_frame(rx.frame, static_cast<double>(now) * 1e-9)) continue;
        // J1939 network management: requests answered for the emulated nodes, claims reported.
        if (nodes->on_frame(rx.frame, static_cast<double>(now) * 1e-9, bus)) {
          ++network;
          continue;
        }
        bool mine = false;
        for (int j = 0; j < n; ++j) {
          const auto& valve = mapping.joints[static_cast<std::size_t>(j)].valve;
          if (!can::is_valve_frame(valve, rx.frame)) continue;
          mine = true;
          double spool = 0.0;
          bool block = false;
          if (can::decode_valve_command(valve, rx.frame, spool, block)) {
            command.spool[j] = spool;
            last_command_ns[static_cast<std::size_t>(j)] = now;
            ++commands;
          } else {
            ++bad;
          }
        }
        if (!mine) ++other;
      }
      // A section whose commands stop falls back to neutral (the valve's own fail-safe); without
      // a live heartbeat (when the mapping has one) every section does (the machine's supervisor).
      const bool alive = !heartbeat || heartbeat->alive(static_cast<double>(now) * 1e-9);
      if (heartbeat && alive != heartbeat_ok) {
        std::printf("craneassist emulate: %.3f s: heartbeat %s\n", static_cast<double>(now) * 1e-9,
                    alive ? "alive, sections enabled" : "lost or disabled, every section blocked");
        std::fflush(stdout);
        heartbeat_ok = alive;
      }
      for (int j = 0; j < n; ++j) {
        if (!alive || now - last_command_ns[static_cast<std::size_t>(j)] > command_timeout_ns ||
            nodes->failed(j, static_cast<double>(now) * 1e-9)) {
          command.spool[j] = 0.0;
        }
      }
      sim.write(command);
      // The valves' replies (what they applied) and the nodes' DM1, when the mapping asks.
      nodes->tick(static_cast<double>(now) * 1e-9, command.spool, bus);
      int steps = 0;
      while (sim_ns + step_ns <= now && steps < 100) {
        sim.advance(step);
        sim_ns += step_ns;
        ++steps;
      }
      const std::int64_t lag = now - sim_ns;
      max_lag_ns = std::max(max_lag_ns, lag);
      if (lag > lag_warning_ns) {
        lagging_ns += step_ns * std::max(steps, 1);
        if (now - last_lag_report >= 1000000000) {
          std::printf(
              "craneassist emulate: %.3f s: the simulation is %.0f ms behind the wall clock "
              "(the machine runs slow; %s)\n",
              static_cast<double>(now) * 1e-9, static_cast<double>(lag) * 1e-6,
              steps >= 100 ? "skipping ahead" : "catching up");
          std::fflush(stdout);
          last_lag_report = now;
        }
      }
      if (sim_ns + step_ns <= now) {  // too slow to keep up: skip ahead, counted
        ++behind;
        sim_ns = now;
      }
      if (now >= next_feedback) {
        next_feedback += feedback_ns;
        if (next_feedback <= now) next_feedback = now + feedback_ns;
        sim.read(state);
        for (auto& f : frames) f.data.fill(0);
        std::fill(unmeasured.begin(), unmeasured.end(), 0);
        for (const auto& s : signals) {
          double value = state.q[s.joint];
          // The emulated machine's chamber pressure transmitters (with the simulator's sensor
          // noise and resolution, then the mapping's scaling).
          if (s.kind == 1) value = state.pressure_a_pa[s.joint];
          if (s.kind == 2) value = state.pressure_b_pa[s.joint];
          if (s.kind == 3) value = state.pump.pressure_pa;
          if (s.kind == 4) value = state.pump.flow_m3_s;
          // The swing sensor (the simulator's, with its noise and resolution); a swing the
          // simulator does not measure (a rigid grapple, simulation.swing_sensor: none) is not
          // sent.
          if (s.kind == 5) value = state.swing_radial_rad;
          if (s.kind == 6) value = state.swing_tangential_rad;
          if (!std::isfinite(value)) {
            unmeasured[s.frame] = 1;
            continue;
          }
          can::encode(*s.spec, value, frames[s.frame]);
        }
        for (std::size_t i = 0; i < frames.size(); ++i) {
          const auto& f = frames[i];
          if (unmeasured[i]) continue;
          if (bus.send(f) == can::SendStatus::kOk) {
            ++sent;
          } else {
            ++send_failed;
          }
        }
      }
      const std::int64_t wake = start + (now / step_ns + 1) * step_ns;
      timespec ts{static_cast<time_t>(wake / 1000000000), static_cast<long>(wake % 1000000000)};
      clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
    }
    std::printf(
        "craneassist emulate: stopped after %.2f s: %llu valve commands, %llu bad, %llu other "
        "frames; %llu feedback frames sent, %llu failed; fell behind %llu times; lag max %.1f ms, "
        "over %.0f ms for %.2f s\n",
        static_cast<double>(mono_ns() - start) * 1e-9, commands, bad, other, sent, send_failed,
        behind, static_cast<double>(max_lag_ns) * 1e-6, args.lag_warning_s * 1e3,
        static_cast<double>(lagging_ns) * 1e-9);
    if (nodes->active() || network > 0) {
      std::printf(
          "craneassist emulate: J1939 nodes: %llu replies, DM1 and claims sent, %llu failed; %llu "
          "network management frames received\n",
          static_cast<unsigned long long>(nodes->frames_sent()),
          static_cast<unsigned long long>(nodes->send_failures()), network);
    }
    if (heartbeat) {
      std::printf(
          "craneassist emulate: heartbeat: %llu messages, %llu sequence errors, %llu malformed, "
          "%llu losses\n",
          static_cast<unsigned long long>(heartbeat->messages()),
          static_cast<unsigned long long>(heartbeat->sequence_errors()),
          static_cast<unsigned long long>(heartbeat->malformed()),
          static_cast<unsigned long long>(heartbeat->losses()));
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace craneassist::cli
