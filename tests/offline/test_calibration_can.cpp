// Valve calibration on a machine over CAN, on the in-memory bus (tests/fake_can_bus.hpp): the
// simulated crane stands behind the protocol as `craneassist emulate` does (valve frames in,
// position frames out every 10 ms, in real time), and the sweep runs through can::CanBackend.
// It gives the simulator's table; a stop request and lost feedback end it with every spool
// ramped or blocked, never with a moving section thrown to neutral in one frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "craneassist/can/can_backend.hpp"
#include "craneassist/can/valve_frames.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/valve_table.hpp"
#include "craneassist/offline/calibration.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"
#include "fake_can_bus.hpp"

using namespace craneassist;
using can::testing::FakeCanBus;
using can::testing::FakeCanTransport;

namespace {

constexpr int kLift = 1;

// The simulated crane behind the CAN protocol on the fake bus, stepped at 1 ms in real time in
// its own thread: the latest valve command of each section (neutral until one arrives), every
// joint's position frame every 10 ms until feedback_until_s (then silent, as a dead sensor).
class Emulator {
 public:
  Emulator(const config::CraneConfig& cfg, const can::CanMapping& map, FakeCanBus& bus,
           double feedback_until_s = 1e9)
      : cfg_(cfg), map_(map), end_(bus), feedback_until_s_(feedback_until_s) {
    bus.attach(&end_);
    thread_ = std::thread([this] { run(); });
  }
  ~Emulator() {
    stop_.store(true);
    thread_.join();
  }

 private:
  void run() {
    sim_backend::SimBackend sim(cfg_.model, {cfg_.simulation.step_s, cfg_.simulation.q_initial});
    const int n = cfg_.model.dof();
    valves::ValveCommand command;
    command.spool = dynamics::JointVector::Zero(n);
    valves::MachineState state;
    can::Received rx;
    const auto t0 = std::chrono::steady_clock::now();
    for (long ms = 0; !stop_.load(); ++ms) {
      for (end_.receive(rx); rx.kind != can::ReceiveKind::kNone; end_.receive(rx)) {
        for (int j = 0; j < n; ++j) {
          const auto& valve = map_.joints[static_cast<std::size_t>(j)].valve;
          double spool = 0.0;
          bool block = false;
          if (can::is_valve_frame(valve, rx.frame) &&
              can::decode_valve_command(valve, rx.frame, spool, block)) {
            command.spool[j] = spool;
          }
        }
      }
      sim.write(command);
      sim.advance(1e-3);
      if (ms % 10 == 0 && static_cast<double>(ms) * 1e-3 < feedback_until_s_) {
        sim.read(state);
        for (int j = 0; j < n; ++j) {
          const auto& spec = map_.joints[static_cast<std::size_t>(j)].position;
          can::CanFrame f;
          f.id = spec.id;
          f.extended = spec.extended;
          f.dlc = can::required_dlc(spec);
          can::encode(spec, state.q[j], f);
          end_.send(f);
        }
      }
      std::this_thread::sleep_until(t0 + std::chrono::milliseconds(ms + 1));
    }
  }

  const config::CraneConfig& cfg_;
  const can::CanMapping& map_;
  FakeCanTransport end_;
  double feedback_until_s_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// The K70M mapping without its J1939 network management and supervision (address claim, valve
// replies, DM1): the machine here is only the crane behind the valve and sensor frames, and the
// claim and the supervision have their own tests (test_can_backend).
can::CanMapping k70m_mapping() {
  can::CanMapping map =
      can::load_can_mapping(std::string(CRANEASSIST_SOURCE_DIR) + "/config/can/k70m_can.yaml");
  map.address_claim.reset();
  map.dm1.reset();
  for (auto& joint : map.joints) joint.reply.reset();
  return map;
}

// A short sweep: the top level only, a shorter settle (the lift reaches its speed in about
// 0.4 s), so a whole sweep takes some 6 s of real time.
offline::CalibrationOptions short_sweep() {
  offline::CalibrationOptions options;
  options.levels = {1.0};
  options.settle_s = 0.8;
  return options;
}

// The lift's spool commands on the bus, in order (block counts as 0).
std::vector<double> lift_commands(FakeCanBus& bus, const can::CanMapping& map) {
  std::vector<double> out;
  const auto& valve = map.joints[kLift].valve;
  for (const auto& r : bus.log()) {
    double spool = 0.0;
    bool block = false;
    if (can::is_valve_frame(valve, r.frame) &&
        can::decode_valve_command(valve, r.frame, spool, block)) {
      out.push_back(block ? 0.0 : spool);
    }
  }
  return out;
}

// The largest step by which a frame closes the lift's spool (towards neutral, or through it)
// while it meters flow. The sweep ramps closing at 2 /s: 0.02 per 10 ms loop cycle, a frame every
// 20 ms (30 ms when the loop's ticks and the frame cycle slip). A stop thrown to neutral would
// step by the dead band, 0.53, or more. (Opening is a step, as a sweep level starts.)
double largest_closing_step(const std::vector<double>& commands, double dead_zone) {
  double worst = 0.0;
  for (std::size_t k = 1; k < commands.size(); ++k) {
    const double before = commands[k - 1], after = commands[k];
    const bool closes = after * before < 0.0 || std::abs(after) < std::abs(before);
    if (std::abs(before) > dead_zone && closes) worst = std::max(worst, std::abs(after - before));
  }
  return worst;
}
constexpr double kClosingStepMax = 0.1;

struct Rig {
  config::CraneConfig cfg = config::default_crane_config();
  can::CanMapping map = k70m_mapping();
  FakeCanBus bus;
  FakeCanTransport backend_end{bus};
  std::optional<Emulator> emulator;
  std::optional<can::CanBackend> backend;
  explicit Rig(double feedback_until_s = 1e9) {
    bus.attach(&backend_end);
    emulator.emplace(cfg, map, bus, feedback_until_s);
    can::CanBackendOptions options;
    options.feedback_timeout_s = 0.3;  // a loaded test host may stall the emulator's thread
    backend.emplace(map, cfg.model, backend_end, options);
    std::string why;
    EXPECT_TRUE(backend->activate(2.0, &why)) << why;
  }
};

TEST(CalibrationOverCan, TheSweepThroughTheCanBackendGivesTheSimulatorsTable) {
  Rig rig;
  const auto options = short_sweep();
  std::vector<offline::SweepLogRow> log;
  const auto sweep =
      offline::calibrate_section_on_machine(rig.cfg, *rig.backend, kLift, options, nullptr, &log);
  rig.backend->deactivate();
  ASSERT_EQ(sweep.end, offline::SweepEnd::kComplete) << sweep.reason;
  EXPECT_FALSE(rig.backend->faulted());
  const auto placed = offline::calibrate_section(rig.cfg, kLift, options);
  const auto& r = sweep.section;
  ASSERT_EQ(dynamics::check_valve_table(r.table), "");
  for (const auto& p : r.points) EXPECT_TRUE(p.valid) << p.command;
  // The bus adds 0.01 deg encoder steps and 10 ms feedback to the simulator, and the emulator
  // thread of a loaded test host sends its frames late and in bursts: the level is measured
  // again when its window did not settle (within 3 %), so the error stays within a few per cent.
  const double v_max = rig.cfg.model.cylinders[kLift].v_max_m_s;
  EXPECT_NEAR(r.max_extend_m_s, placed.max_extend_m_s, 0.04 * v_max);
  EXPECT_NEAR(r.max_retract_m_s, placed.max_retract_m_s, 0.04 * v_max);
  const auto level_rows = static_cast<std::size_t>(std::lround(options.settle_s * 100) +
                                                   std::lround(options.measure_s * 100) + 1);
  EXPECT_EQ(log.size() % level_rows, 0u);
  EXPECT_GE(log.size(), 2 * level_rows);
  std::printf(
      "lift over CAN: %.5f / %.5f m/s (sim %.5f / %.5f), %zu levels measured again, "
      "sweep %.1f s\n",
      r.max_retract_m_s, r.max_extend_m_s, placed.max_retract_m_s, placed.max_extend_m_s,
      log.size() / level_rows - 2, sweep.wall_time_s);
  const auto commands = lift_commands(rig.bus, rig.map);
  ASSERT_FALSE(commands.empty());
  EXPECT_EQ(commands.back(), 0.0) << "blocked at the end";
  EXPECT_LE(largest_closing_step(commands, rig.cfg.model.valves.dead_zone), kClosingStepMax);
}

TEST(CalibrationOverCan, AStopRequestRampsTheSpoolsToNeutral) {
  Rig rig;
  std::atomic<bool> stop{false};
  std::thread stopper([&] {
    // In the middle of the first level: the lift at speed.
    const auto t0 = std::chrono::steady_clock::now();
    while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20)) {
      const auto commands = lift_commands(rig.bus, rig.map);
      if (!commands.empty() && std::abs(commands.back()) == 1.0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    stop.store(true);
  });
  const auto sweep =
      offline::calibrate_section_on_machine(rig.cfg, *rig.backend, kLift, short_sweep(), &stop);
  stopper.join();
  rig.backend->deactivate();
  EXPECT_EQ(sweep.end, offline::SweepEnd::kStopRequested);
  EXPECT_FALSE(rig.backend->faulted());
  EXPECT_TRUE(sweep.section.points.empty()) << "stopped in the first level";
  const auto commands = lift_commands(rig.bus, rig.map);
  ASSERT_FALSE(commands.empty());
  double top = 0.0;
  for (double c : commands) top = std::max(top, std::abs(c));
  EXPECT_GT(top, 0.99) << "the lift was at full command when the stop came";
  EXPECT_EQ(commands.back(), 0.0);
  EXPECT_LE(largest_closing_step(commands, rig.cfg.model.valves.dead_zone), kClosingStepMax);
}

TEST(CalibrationOverCan, LostFeedbackEndsTheSweepWithTheMachinesReason) {
  Rig rig(1.5);  // the sensors fall silent after 1.5 s
  const auto sweep =
      offline::calibrate_section_on_machine(rig.cfg, *rig.backend, kLift, short_sweep());
  EXPECT_EQ(sweep.end, offline::SweepEnd::kMachineFault);
  EXPECT_NE(sweep.reason.find("no position frame"), std::string::npos) << sweep.reason;
  EXPECT_TRUE(rig.backend->faulted());
  EXPECT_LT(sweep.wall_time_s, 3.0);
  rig.backend->deactivate();
}

}  // namespace
