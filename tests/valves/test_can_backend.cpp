// CanBackend on an in-memory bus (no kernel CAN needed): valve command frames, feedback decoding,
// staleness, the watchdog, fault latching and re-enable, send errors, bus errors, the log.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <string>
#include <thread>

#include "allocation_counter.hpp"
#include "craneassist/can/address_claim.hpp"
#include "craneassist/can/can_backend.hpp"
#include "craneassist/can/dm1.hpp"
#include "craneassist/can/heartbeat.hpp"
#include "craneassist/can/valve_frames.hpp"
#include "craneassist/config/crane_config.hpp"
#include "fake_can_bus.hpp"
#include "realtime_thread.hpp"

namespace craneassist::can {
namespace {

using testing::FakeCanBus;
using testing::FakeCanTransport;
using namespace std::chrono_literals;

std::string hex(const CanFrame& f) {
  char buf[kCandumpLineCapacity];
  std::size_t n = 0;
  format_candump(f, 0, "x", buf, n);
  return std::string(buf, n).substr(std::string("(0.000000) x ").size());
}

// The K70M mapping as shipped: with its address claim, valve replies and DM1 supervision.
CanMapping k70m_full_mapping() {
  return load_can_mapping(std::string(CRANEASSIST_SOURCE_DIR) + "/config/can/k70m_can.yaml");
}

// Without the address claim and the supervision: the cases that test the rest of the backend
// (frames, feedback, watchdog, heartbeat) need no 250 ms claim and no valve playing along. The
// claim and the supervision have their own cases below.
CanMapping k70m_mapping() {
  CanMapping m = k70m_full_mapping();
  m.address_claim.reset();
  m.dm1.reset();
  for (auto& j : m.joints) j.reply.reset();
  return m;
}

// Plays the machine's sensors: the position (and pressure) frames of every joint.
void send_feedback(FakeCanTransport& sensors, const CanMapping& map, const double* q) {
  for (std::size_t i = 0; i < map.joints.size(); ++i) {
    const auto& spec = map.joints[i].position;
    CanFrame f;
    f.id = spec.id;
    f.extended = spec.extended;
    f.dlc = required_dlc(spec);
    ASSERT_EQ(encode(spec, q[i], f), SignalStatus::kOk);
    sensors.send(f);
  }
}

// Is this frame a block/neutral command of joint i?
bool is_block(const JointMapping& j, const CanFrame& f) {
  double spool = 1.0;
  bool block = false;
  return is_valve_frame(j.valve, f) && decode_valve_command(j.valve, f, spool, block) && block &&
         spool == 0.0;
}

struct Rig {
  // The rig's cycles and the backend's watchdog (started after it) as a machine runs them: a busy
  // host would otherwise hold this thread back past the watchdog's 80 ms ("control loop frozen").
  test::RealtimeThread realtime;
  CanMapping map = k70m_mapping();
  config::CraneConfig cfg = config::default_crane_config();
  FakeCanBus bus;
  FakeCanTransport backend_end{bus}, sensors{bus};
  double q[4] = {0.1, 0.2, -0.3, 1.0};
  // wall_clock_step_us: FakeCanBus's, set before a backend (and its watchdog thread) exists.
  explicit Rig(std::int64_t wall_clock_step_us = 0) {
    bus.wall_clock_step_us = wall_clock_step_us;
    bus.attach(&backend_end);
    bus.attach(&sensors);
  }
  // One round of the position frames of every joint.
  void feedback() { send_feedback(sensors, map, q); }
  // Every valve frame on the bus since the last clear_log() is block.
  void expect_only_block_on_the_bus() {
    for (const auto& rx : bus.log()) {
      for (const auto& j : map.joints) {
        if (is_valve_frame(j.valve, rx.frame)) {
          EXPECT_TRUE(is_block(j, rx.frame));
        }
      }
    }
  }
  // The bus log holds block for every section at once, then a heartbeat in state disabled.
  void expect_all_blocked_and_disabled_heartbeat() {
    const auto log = bus.log();
    ASSERT_EQ(log.size(), 5u);
    for (std::size_t j = 0; j < 4; ++j) EXPECT_TRUE(is_block(map.joints[j], log[j].frame)) << j;
    Heartbeat hb;
    ASSERT_TRUE(decode_heartbeat(*map.heartbeat, log[4].frame, hb));
    EXPECT_EQ(hb.state, HeartbeatState::kDisabled);
  }
};

// Where most cases start: a backend on the rig that has read the feedback once and is enabled.
struct EnabledRig : Rig {
  CanBackend backend;
  valves::MachineState state;
  valves::BackendStatus first_read;
  explicit EnabledRig(std::int64_t wall_clock_step_us = 0)
      : Rig(wall_clock_step_us), backend(map, cfg.model, backend_end) {
    feedback();
    first_read = backend.read(state);
    backend.enable();
  }
  // The kernel reports a controller/bus error to the backend's socket.
  void bus_error(std::uint32_t flags) {
    Received err;
    err.kind = ReceiveKind::kBusError;
    err.bus_error = flags;
    err.timestamp_us = realtime_now_us();
    backend_end.deliver(err);
  }
  // n control cycles at 100 Hz, each with fresh feedback, a read and a write of cmd.
  void run_cycles(int n, const valves::ValveCommand& cmd) { run_cycles(n, n, cmd); }
  // The same, but the sensors fall silent after the first `fed` cycles (the reads before are
  // kOk). Returns how long after the last feedback the backend had latched its fault.
  std::chrono::steady_clock::duration run_cycles(int n, int fed, const valves::ValveCommand& cmd) {
    const auto t0 = std::chrono::steady_clock::now();
    auto last_feedback = t0;
    std::chrono::steady_clock::time_point faulted_at{};
    for (int k = 0; k < n; ++k) {
      if (k < fed) {
        feedback();
        last_feedback = std::chrono::steady_clock::now();
        EXPECT_EQ(backend.read(state), valves::BackendStatus::kOk) << "fresh while frames come";
      } else {
        backend.read(state);
      }
      backend.write(cmd);
      if (backend.faulted() && faulted_at == std::chrono::steady_clock::time_point{}) {
        faulted_at = std::chrono::steady_clock::now();
      }
      std::this_thread::sleep_until(t0 + (k + 1) * 10ms);
    }
    return faulted_at - last_feedback;
  }
};

valves::ValveCommand spool_command(double spool) {
  valves::ValveCommand cmd;
  cmd.spool = dynamics::JointVector::Constant(4, spool);
  return cmd;
}

TEST(ValveFrames, AvcAndCurrentCommandsFromTheSpool) {
  const auto map = k70m_mapping();
  CanFrame f;
  ASSERT_TRUE(encode_valve_command(map.joints[0].valve, 0.5, f));
  EXPECT_EQ(hex(f), "0CFE3080#7DFD31007DFFFFFF");  // the known ISO 11783 vector
  ASSERT_TRUE(encode_valve_command(map.joints[1].valve, -0.25, f));
  EXPECT_EQ(f.id, 0x0CFE3180u);
  EXPECT_EQ(f.data[2] & 0x0F, 2);  // retract
  ASSERT_TRUE(encode_valve_command(map.joints[2].valve, 0.0, f));
  EXPECT_EQ(f.data[2] & 0x0F, 0);  // block
  EXPECT_EQ(f.data[0], 0);
  ASSERT_TRUE(encode_valve_command(map.joints[3].valve, -0.5, f));  // -400 mA of 800
  EXPECT_EQ(hex(f), "210#70FE");
  for (std::size_t j = 0; j < 4; ++j) {
    for (double s : {-1.0, -0.3, 0.0, 0.42, 1.0}) {
      ASSERT_TRUE(encode_valve_command(map.joints[j].valve, s, f));
      double back = 9.0;
      bool block = false;
      ASSERT_TRUE(is_valve_frame(map.joints[j].valve, f));
      ASSERT_TRUE(decode_valve_command(map.joints[j].valve, f, back, block));
      EXPECT_NEAR(back, s, 2e-3) << j;
      EXPECT_EQ(block, s == 0.0);
    }
  }
  ASSERT_TRUE(encode_valve_command(map.joints[0].valve, NAN, f));
  EXPECT_EQ(f.data[2] & 0x0F, 0);  // non-finite: block
  CanFrame other = f;
  other.id = 0x0CFE3181;  // another source address
  EXPECT_FALSE(is_valve_frame(map.joints[0].valve, other));
}

TEST(CanBackend, DecodesFeedbackInSiAndDisabledSendsBlock) {
  Rig r;
  CanBackend backend(r.map, r.cfg.model, r.backend_end);
  valves::MachineState state;
  EXPECT_EQ(backend.read(state), valves::BackendStatus::kNoData);
  EXPECT_FALSE(state.valid);
  r.feedback();
  CanFrame p;
  p.id = 0x302;
  p.dlc = 4;
  p.data = {0x10, 0x27, 0xE8, 0x03};  // 100 bar, 10 bar
  r.sensors.send(p);
  EXPECT_EQ(backend.read(state), valves::BackendStatus::kOk);
  ASSERT_TRUE(state.valid);
  EXPECT_NEAR(state.q[0], 0.1, 1e-4);   // rad, 0.01 deg resolution
  EXPECT_NEAR(state.q[2], -0.3, 1e-4);  // Motorola encoder
  EXPECT_NEAR(state.q[3], 1.0, 1e-4);   // m, 0.1 mm resolution
  const auto& cyl = r.cfg.model.cylinders[1];
  EXPECT_NEAR(state.load_pressure_pa[1], 100e5 - 10e5 * cyl.area_b_m2 / cyl.area_a_m2, 1.0);
  // Both chambers, for the crane scale (docs/loads.md); the simulator's truth is not known.
  EXPECT_TRUE(state.chamber_pressures);
  EXPECT_NEAR(state.pressure_a_pa[1], 100e5, 1.0);
  EXPECT_NEAR(state.pressure_b_pa[1], 10e5, 1.0);
  EXPECT_TRUE(std::isnan(state.pressure_b_pa[3]));  // the extension's rod side has no signal
  EXPECT_TRUE(std::isnan(state.payload_truth_kg));

  r.bus.clear_log();
  valves::ValveCommand cmd;
  cmd.spool = dynamics::JointVector::Constant(4, 0.5);
  backend.write(cmd);  // not enabled yet: block, and the heartbeat says disabled
  r.expect_all_blocked_and_disabled_heartbeat();
  EXPECT_FALSE(backend.faulted());
}

TEST(CanBackend, SendsAtTheMappingCycleNotEveryWrite) {
  EnabledRig r;
  r.bus.clear_log();
  r.run_cycles(10, spool_command(0.3));  // 100 ms at 100 Hz, cycle 20 ms: 5 frames per joint
  const auto log = r.bus.log();
  int slew = 0;
  for (const auto& rx : log) {
    if (rx.frame.id == 0x0CFE3080u) {
      ++slew;
      EXPECT_EQ(rx.frame.data[2] & 0x0F, 1);  // extend
    }
  }
  EXPECT_GE(slew, 4);
  EXPECT_LE(slew, 6);
  EXPECT_FALSE(r.backend.faulted());
}

// A control loop that runs late now and then (every 3rd cycle 4 ms late) keeps the 20 ms command
// period: a late send keeps its slot in the schedule instead of pushing the next one a cycle on
// (which made 26-30 ms gaps: about 35 commands instead of 50 in a second).
TEST(CanBackend, ALateCycleDoesNotStretchTheCommandPeriod) {
  EnabledRig r;
  r.bus.clear_log();
  const auto cmd = spool_command(0.3);
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < 100; ++k) {  // 1 s at 100 Hz
    std::this_thread::sleep_until(t0 + k * 10ms + (k % 3 == 0 ? 4ms : 0ms));
    r.feedback();
    r.backend.read(r.state);
    r.backend.write(cmd);
  }
  int slew = 0, heartbeats = 0;
  for (const auto& rx : r.bus.log()) {
    slew += rx.frame.id == 0x0CFE3080u;
    heartbeats += is_heartbeat_frame(*r.map.heartbeat, rx.frame);
  }
  // 50 on time; a slow (sanitizer) build may lose one at the start or end.
  EXPECT_GE(slew, 47) << "one command per 20 ms over 1 s";
  EXPECT_LE(slew, 51);
  EXPECT_GE(heartbeats, 47);
}

// The valves see a command every 20 ms: the backend says so, and the controller's valve
// follower leaves out its one-cycle dead-zone lead (tests/control/test_valve_command_period.cpp).
TEST(CanBackend, ReportsItsValveCommandPeriod) {
  Rig r;
  CanBackend backend(r.map, r.cfg.model, r.backend_end);
  EXPECT_DOUBLE_EQ(backend.command_period_s(), 0.02);
  const valves::MachineInterface& machine = backend;
  EXPECT_DOUBLE_EQ(machine.command_period_s(), 0.02);
}

TEST(CanBackend, LostFeedbackLatchesBlockUntilEnable) {
  EnabledRig r;
  auto& backend = r.backend;
  auto& state = r.state;
  const auto cmd = spool_command(0.3);
  const auto block_all_after = r.run_cycles(20, 5, cmd);
  ASSERT_TRUE(backend.faulted());
  EXPECT_EQ(backend.fault_reason(), FaultReason::kFeedbackLost);
  EXPECT_NE(backend.fault_text().find("no position frame"), std::string::npos);
  EXPECT_LT(block_all_after, 100ms);
  EXPECT_FALSE(state.valid);
  // The last commands on the bus are block, and they stay block with fresh feedback again.
  r.bus.clear_log();
  for (int k = 0; k < 5; ++k) {
    r.feedback();
    EXPECT_EQ(backend.read(state), valves::BackendStatus::kFault);
    backend.write(cmd);
    std::this_thread::sleep_for(10ms);
  }
  r.expect_only_block_on_the_bus();
  backend.enable();  // the deliberate re-enable
  r.feedback();
  EXPECT_EQ(backend.read(state), valves::BackendStatus::kOk);
  EXPECT_TRUE(state.valid);
  EXPECT_EQ(backend.counters().faults, 1u);
}

// Lost feedback is timed on CLOCK_MONOTONIC, not on the frames' wall-clock stamps: frames stamped
// an hour ahead (the wall clock stepped back an hour after they came) do not stay fresh for an
// hour; frames stamped an hour behind (stepped forward) are fresh while they come.
TEST(CanBackend, LostFeedbackIsTimedOnTheMonotonicClockThroughAWallClockStep) {
  for (const std::int64_t step_us : {std::int64_t{3600000000}, std::int64_t{-3600000000}}) {
    SCOPED_TRACE(step_us);
    EnabledRig r(step_us);
    EXPECT_EQ(r.first_read, valves::BackendStatus::kOk);
    const auto faulted_after = r.run_cycles(30, 5, spool_command(0.3));
    ASSERT_TRUE(r.backend.faulted());
    EXPECT_EQ(r.backend.fault_reason(), FaultReason::kFeedbackLost);
    EXPECT_LT(faulted_after, 100ms);
  }
}

TEST(CanBackend, WatchdogBlocksEverySectionWhenTheLoopFreezes) {
  EnabledRig r;
  auto& backend = r.backend;
  backend.write(spool_command(-0.4));
  const auto frozen_at = realtime_now_us();
  r.bus.clear_log();
  std::this_thread::sleep_for(250ms);  // the control loop stops calling write()
  ASSERT_TRUE(backend.faulted());
  EXPECT_EQ(backend.fault_reason(), FaultReason::kLoopFrozen);
  const auto log = r.bus.log();
  TimestampUs all_blocked = 0;
  bool seen[4] = {};
  for (const auto& rx : log) {
    for (std::size_t j = 0; j < 4; ++j) {
      if (is_block(r.map.joints[j], rx.frame)) seen[j] = true;
    }
    if (all_blocked == 0 && seen[0] && seen[1] && seen[2] && seen[3]) all_blocked = rx.timestamp_us;
  }
  ASSERT_NE(all_blocked, 0);
  // The requirement: every section blocked within 100 ms of the last write(); the loop timeout
  // is 80 ms, plus a watchdog step (5 ms) and scheduling.
  EXPECT_GT(all_blocked - frozen_at, 80000);
  EXPECT_LT(all_blocked - frozen_at, 100000);
  EXPECT_GT(backend.counters().watchdog_block_frames, 4u);
  // The heartbeat comes from the control loop only: a frozen loop stops it, so the machine's
  // supervisor sees the loss even if it missed the block commands.
  for (const auto& rx : log) EXPECT_FALSE(is_heartbeat_frame(*r.map.heartbeat, rx.frame));
  std::printf("frozen loop: every section blocked %.1f ms after the last write()\n",
              static_cast<double>(all_blocked - frozen_at) * 1e-3);
}

// Collects the heartbeats on the bus.
std::vector<Heartbeat> heartbeats(FakeCanBus& bus, const HeartbeatSpec& spec) {
  std::vector<Heartbeat> out;
  for (const auto& rx : bus.log()) {
    Heartbeat hb;
    if (decode_heartbeat(spec, rx.frame, hb)) out.push_back(hb);
  }
  return out;
}

TEST(CanBackend, HeartbeatCountsUpAtItsCycleAndReportsTheState) {
  EnabledRig r;
  auto& backend = r.backend;
  const auto cmd = spool_command(0.3);
  r.bus.clear_log();
  r.run_cycles(20, cmd);  // 200 ms at 100 Hz; heartbeat cycle 20 ms
  auto hbs = heartbeats(r.bus, *r.map.heartbeat);
  ASSERT_GE(hbs.size(), 9u);
  ASSERT_LE(hbs.size(), 11u);
  for (std::size_t i = 1; i < hbs.size(); ++i) {
    EXPECT_EQ(hbs[i].counter, static_cast<std::uint8_t>(hbs[i - 1].counter + 1));
    EXPECT_EQ(hbs[i].state, HeartbeatState::kEnabled);
  }
  EXPECT_EQ(backend.counters().heartbeats_sent, hbs.size());

  // Feedback stops: the fault latches and the heartbeat carries it, with its reason.
  r.bus.clear_log();
  for (int k = 0; k < 12; ++k) {
    backend.read(r.state);
    backend.write(cmd);
    std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(backend.faulted());
  hbs = heartbeats(r.bus, *r.map.heartbeat);
  ASSERT_FALSE(hbs.empty());
  EXPECT_EQ(hbs.back().state, HeartbeatState::kFault);
  EXPECT_EQ(hbs.back().reason, static_cast<std::uint8_t>(FaultReason::kFeedbackLost));
}

TEST(CanBackend, DisableBlocksEverySectionAtOnceWithoutAFault) {
  EnabledRig r;
  auto& backend = r.backend;
  const auto cmd = spool_command(0.5);
  backend.write(cmd);
  r.bus.clear_log();
  backend.disable();  // the normal end of a run, 0 ms after the last write
  r.expect_all_blocked_and_disabled_heartbeat();
  EXPECT_FALSE(backend.enabled());
  // No more writes: not a frozen loop (no fault), but the watchdog keeps every section blocked.
  r.bus.clear_log();
  std::this_thread::sleep_for(150ms);
  EXPECT_FALSE(backend.faulted());
  int blocks = 0;
  for (const auto& rx : r.bus.log()) {
    for (const auto& j : r.map.joints) {
      if (is_valve_frame(j.valve, rx.frame)) {
        EXPECT_TRUE(is_block(j, rx.frame));
        ++blocks;
      }
    }
  }
  EXPECT_GE(blocks, 4 * 5);  // each section at its 20 ms cycle
  // Writes after disable() send block too.
  r.bus.clear_log();
  std::this_thread::sleep_for(25ms);
  backend.write(cmd);
  r.expect_only_block_on_the_bus();
}

TEST(CanBackend, RejectsAMappingThatDoesNotFitTheCrane) {
  Rig r;
  auto expect_rejected = [&](const CanMapping& map, const std::string& part) {
    try {
      CanBackend backend(map, r.cfg.model, r.backend_end);
      ADD_FAILURE() << "accepted; expected: " << part;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  CanMapping swapped = r.map;  // the extension's length sensor on the slew
  std::swap(swapped.joints[0].position, swapped.joints[3].position);
  std::swap(swapped.joints[0].position_kind, swapped.joints[3].position_kind);
  expect_rejected(swapped, "joint 'slew': the crane's joint is revolute");
  CanMapping narrow = r.map;  // the lift encoder's range ends inside the joint range
  narrow.joints[1].position.maximum = r.cfg.model.joints[1].q_max - 0.1;
  expect_rejected(narrow, "joint 'lift': the position signal's min/max do not cover");
  CanMapping renamed = r.map;
  renamed.joints[2].name = "boom";
  expect_rejected(renamed, "joint 3 is 'boom'");
}

TEST(CanBackend, PumpPressureAndFlowFromTheBus) {
  Rig r;
  ASSERT_TRUE(r.map.pump.pressure && r.map.pump.flow);
  CanBackend backend(r.map, r.cfg.model, r.backend_end);
  valves::MachineState state;
  r.feedback();
  backend.read(state);
  EXPECT_EQ(state.pump.flow_m3_s, 0.0);  // no pump frame yet: unmeasured
  CanFrame f;
  f.id = r.map.pump.pressure->id;
  f.dlc = 4;
  ASSERT_EQ(encode(*r.map.pump.pressure, 180e5, f), SignalStatus::kOk);     // 180 bar
  ASSERT_EQ(encode(*r.map.pump.flow, 90e-3 / 60.0, f), SignalStatus::kOk);  // 90 L/min
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < 10; ++k) {
    r.feedback();
    r.sensors.send(f);
    backend.read(state);
    std::this_thread::sleep_until(t0 + (k + 1) * 10ms);
  }
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_NEAR(state.pump.pressure_pa, 180e5, 1e3);
  EXPECT_NEAR(state.pump.flow_m3_s, 1.5e-3, 1e-6);
  EXPECT_NEAR(state.pump.power_w, 27e3, 30.0);
  // Integrated between reads: about 27 kW over the 9 intervals after the first measured read.
  EXPECT_GT(state.pump.energy_j, 27e3 * 0.07);
  EXPECT_LT(state.pump.energy_j, 27e3 * elapsed);
  // The pump frames stop: unmeasured again after the feedback timeout, the energy is kept.
  const double energy = state.pump.energy_j;
  std::this_thread::sleep_for(60ms);
  r.feedback();
  backend.read(state);
  EXPECT_EQ(state.pump.flow_m3_s, 0.0);
  EXPECT_EQ(state.pump.energy_j, energy);
  EXPECT_FALSE(backend.faulted());  // informational, never a fault
}

// The grapple's swing sensor (docs/can.md, "Swing sensor"): both angles in SI, the swing from the
// vertical as the simulator measures it; unmeasured (NaN) before the first frame, once the frames
// stop and after a malformed frame, never a fault.
TEST(CanBackend, SwingSensorFromTheBus) {
  Rig r;
  ASSERT_TRUE(r.map.grapple.swing_radial && r.map.grapple.swing_tangential);
  CanBackend backend(r.map, r.cfg.model, r.backend_end);
  valves::MachineState state;
  r.feedback();
  backend.read(state);
  EXPECT_TRUE(std::isnan(state.swing_rad));  // no swing frame yet
  CanFrame f;
  f.id = r.map.grapple.swing_radial->id;
  f.dlc = 4;
  const double radial = 3.0 * M_PI / 180.0, tangential = -4.0 * M_PI / 180.0;
  ASSERT_EQ(encode(*r.map.grapple.swing_radial, radial, f), SignalStatus::kOk);
  ASSERT_EQ(encode(*r.map.grapple.swing_tangential, tangential, f), SignalStatus::kOk);
  r.feedback();
  r.sensors.send(f);
  backend.read(state);
  const double bit = 0.01 * M_PI / 180.0;
  EXPECT_NEAR(state.swing_radial_rad, radial, bit);
  EXPECT_NEAR(state.swing_tangential_rad, tangential, bit);
  EXPECT_NEAR(state.swing_rad, std::atan(std::hypot(std::tan(radial), std::tan(tangential))),
              2.0 * bit);
  EXPECT_TRUE(state.valid);
  // A frame too short for the tangential angle: counted, the swing not updated by it.
  CanFrame shorter = f;
  shorter.dlc = 2;
  r.feedback();
  r.sensors.send(shorter);
  backend.read(state);
  EXPECT_FALSE(backend.faulted());
  // The frames stop: unmeasured after the feedback timeout, never a fault.
  std::this_thread::sleep_for(60ms);
  r.feedback();
  backend.read(state);
  EXPECT_TRUE(std::isnan(state.swing_rad));
  EXPECT_TRUE(std::isnan(state.swing_radial_rad));
  EXPECT_TRUE(state.valid);
  EXPECT_FALSE(backend.faulted());
}

TEST(HeartbeatMonitor, AliveOnlyWhileTheCounterAdvancesInStateEnabled) {
  const HeartbeatSpec spec{0x18FF0080, true, 0.02, 0.1};
  HeartbeatMonitor mon(spec);
  CanFrame f;
  Heartbeat hb;
  hb.state = HeartbeatState::kEnabled;
  hb.counter = 254;
  auto feed = [&](double t) {
    encode_heartbeat(spec, hb, f);
    EXPECT_TRUE(mon.on_frame(f, t));
    hb.counter = static_cast<std::uint8_t>(hb.counter + 1);  // 255 wraps to 0
  };
  EXPECT_FALSE(mon.alive(0.0));
  feed(0.00);  // the first message alone proves nothing
  EXPECT_FALSE(mon.alive(0.00));
  feed(0.02);  // 254 -> 255
  EXPECT_TRUE(mon.alive(0.02));
  feed(0.04);  // 255 -> 0 wraps
  EXPECT_TRUE(mon.alive(0.10));
  EXPECT_TRUE(mon.alive(0.13));
  EXPECT_FALSE(mon.alive(0.15));  // 110 ms after the last advancing message
  EXPECT_EQ(mon.losses(), 1u);
  // A repeated counter (a stuck sender) does not refresh.
  hb.counter = static_cast<std::uint8_t>(hb.counter - 1);
  feed(0.16);
  EXPECT_FALSE(mon.alive(0.16));
  EXPECT_EQ(mon.sequence_errors(), 1u);
  feed(0.18);
  EXPECT_TRUE(mon.alive(0.18));
  // The sender reports disabled or a fault: not alive at once.
  hb.state = HeartbeatState::kFault;
  feed(0.19);
  EXPECT_FALSE(mon.alive(0.19));
  EXPECT_EQ(mon.last().state, HeartbeatState::kFault);
  // Other frames are not the heartbeat; a short or unknown-state frame is malformed.
  CanFrame other;
  other.id = 0x18FF0081;
  other.extended = true;
  EXPECT_FALSE(mon.on_frame(other, 0.2));
  encode_heartbeat(spec, hb, f);
  f.data[1] = 7;
  EXPECT_TRUE(mon.on_frame(f, 0.2));
  f.dlc = 2;
  EXPECT_TRUE(mon.on_frame(f, 0.2));
  EXPECT_EQ(mon.malformed(), 2u);
  EXPECT_EQ(mon.messages(), 6u);
}

TEST(CanBackend, WrongDlcOnFeedbackLatchesAndUnknownFramesAreOnlyCounted) {
  EnabledRig r;
  auto& backend = r.backend;
  auto& state = r.state;
  CanFrame junk;
  junk.id = 0x555;
  junk.dlc = 3;
  r.sensors.send(junk);
  junk.id = 0x7FF;
  r.sensors.send(junk);
  r.feedback();
  EXPECT_EQ(backend.read(state), valves::BackendStatus::kOk);
  EXPECT_EQ(backend.counters().unknown_frames, 2u);
  CanFrame bad;
  bad.id = 0x18FF1022;
  bad.extended = true;
  bad.dlc = 1;  // the lift encoder needs 2 bytes
  r.sensors.send(bad);
  EXPECT_EQ(backend.read(state), valves::BackendStatus::kFault);
  EXPECT_EQ(backend.fault_reason(), FaultReason::kBadFeedbackFrame);
  EXPECT_NE(backend.fault_text().find("lift"), std::string::npos);
  EXPECT_EQ(backend.counters().bad_frames, 1u);
}

TEST(CanBackend, BusOffErrorPassiveAndControllerRestartLatch) {
  const std::pair<std::uint32_t, FaultReason> cases[] = {
      {kBusOff, FaultReason::kBusOff},
      {kErrorPassive, FaultReason::kErrorPassive},
      {kControllerRestarted, FaultReason::kControllerRestarted},
      {kBusOff | kControllerRestarted, FaultReason::kBusOff}};
  for (const auto& [flag, reason] : cases) {
    EnabledRig r;
    r.bus_error(flag);
    r.feedback();
    EXPECT_EQ(r.backend.read(r.state), valves::BackendStatus::kFault) << flag;
    EXPECT_EQ(r.backend.fault_reason(), reason) << flag;
    EXPECT_EQ(r.backend.counters().bus_error_frames, 1u);
  }
}

TEST(CanBackend, AckProtocolAndWarningErrorsAreOnlyCounted) {
  EnabledRig r;
  for (std::uint32_t flag : {std::uint32_t{kBusErrorOther}, std::uint32_t{kErrorWarning},
                             std::uint32_t{kBusErrorOther | kErrorWarning}}) {
    r.bus_error(flag);
  }
  r.feedback();
  EXPECT_EQ(r.backend.read(r.state), valves::BackendStatus::kOk);
  EXPECT_FALSE(r.backend.faulted());
  EXPECT_EQ(r.backend.counters().bus_error_frames, 3u);
}

TEST(CanBackend, ConsecutiveSendErrorsLatch) {
  EnabledRig r;
  r.backend_end.next_send_status = SendStatus::kQueueFull;
  r.backend.write(spool_command(0.1));  // 4 sections and the heartbeat, 5 failed sends, no waiting
  EXPECT_TRUE(r.backend.faulted());
  EXPECT_EQ(r.backend.fault_reason(), FaultReason::kSendError);
  EXPECT_EQ(r.backend.counters().send_queue_full, 5u);
}

TEST(CanBackend, CandumpLogHoldsSentAndReceivedFrames) {
  const std::string path = ::testing::TempDir() + "/can_backend_log.txt";
  {
    Rig r;
    CanBackendOptions options;
    options.candump_log = path;
    CanBackend backend(r.map, r.cfg.model, r.backend_end, options);
    valves::MachineState state;
    r.feedback();
    backend.read(state);
    valves::ValveCommand cmd;
    cmd.spool = dynamics::JointVector::Zero(4);
    backend.write(cmd);
  }
  std::ifstream in(path);
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) {
    CandumpRecord rec;
    ASSERT_EQ(parse_candump(line, rec), CandumpStatus::kOk) << line;
    EXPECT_EQ(rec.iface, "fake0");
    ++lines;
  }
  EXPECT_EQ(lines, 9);  // 4 positions received, 4 commands and the heartbeat sent
}

// ---- J1939 address claim (docs/can.md, "Address claim") ----

constexpr std::uint64_t kK70mName = 0x3000820000000C1Aull;  // config/can/k70m_can.yaml

// The K70M mapping with its address claim, without the valve supervision.
CanMapping claiming_mapping() {
  CanMapping m = k70m_full_mapping();
  m.dm1.reset();
  for (auto& j : m.joints) j.reply.reset();
  return m;
}

bool from_address(const CanFrame& f, std::uint8_t address) {
  return f.extended && (f.id & 0xFFu) == address;
}

bool is_claim(const CanFrame& f, std::uint8_t source, std::uint64_t name) {
  std::uint64_t n = 0;
  std::uint8_t sa = 0;
  return j1939::decode_address_claimed(f, n, sa) && sa == source && n == name;
}

// A claim or request from another node, waiting in the backend's receive queue.
void deliver(FakeCanTransport& to, const CanFrame& f) {
  Received r;
  r.kind = ReceiveKind::kFrame;
  r.frame = f;
  r.timestamp_us = realtime_now_us();
  to.deliver(r);
}

// The frames the backend sent (the bus log holds the sensors' frames too).
std::vector<Received> sent_by_backend(FakeCanBus& bus, const CanMapping& map) {
  std::vector<Received> out;
  for (const auto& rx : bus.log()) {
    bool feedback = false;
    for (const auto& j : map.joints) {
      feedback = feedback || (rx.frame.id == j.position.id && rx.frame.extended);
    }
    if (!feedback) out.push_back(rx);
  }
  return out;
}

TEST(CanBackendAddressClaim, ClaimsBeforeAnyCommandThenWaitsTheClaimTime) {
  Rig r;
  r.map = claiming_mapping();
  CanBackend backend(r.map, r.cfg.model, r.backend_end);
  valves::MachineState state;
  r.feedback();
  backend.read(state);
  backend.write(spool_command(0.5));   // not claimed yet: nothing at all goes out
  std::this_thread::sleep_for(100ms);  // nor from the watchdog
  EXPECT_TRUE(sent_by_backend(r.bus, r.map).empty());
  EXPECT_EQ(backend.address_claim_state(), j1939::ClaimState::kIdle);

  const auto t0 = std::chrono::steady_clock::now();
  std::string why;
  ASSERT_TRUE(backend.activate(2.0, &why)) << why;
  const auto took = std::chrono::steady_clock::now() - t0;
  EXPECT_GE(took, 250ms);  // J1939-81: 250 ms for a contending claim
  EXPECT_LT(took, 500ms);  // 250 ms and the reads around it, on a loaded host
  EXPECT_EQ(backend.address_claim_state(), j1939::ClaimState::kClaimed);
  backend.write(spool_command(0.5));
  const auto sent = sent_by_backend(r.bus, r.map);
  ASSERT_GE(sent.size(), 6u);  // the claim, 4 commands, the heartbeat
  EXPECT_TRUE(is_claim(sent[0].frame, 0x80, kK70mName));
  EXPECT_EQ(sent[0].frame.id, 0x18EEFF80u);
  for (std::size_t i = 1; i < sent.size(); ++i) {
    EXPECT_FALSE(is_claim(sent[i].frame, 0x80, kK70mName)) << "claimed once";
    EXPECT_GE(sent[i].timestamp_us - sent[0].timestamp_us, 250000) << "sent within the claim time";
  }
  r.feedback();
  EXPECT_EQ(backend.read(state), valves::BackendStatus::kOk);
  EXPECT_EQ(backend.counters().claim_frames_sent, 1u);
}

TEST(CanBackendAddressClaim, LosesToAHigherPriorityNameAndSendsNothingFromTheAddress) {
  Rig r;
  r.map = claiming_mapping();
  CanBackend backend(r.map, r.cfg.model, r.backend_end);
  r.feedback();
  CanFrame rival;
  j1939::encode_address_claimed(0x0000000000000001ull, 0x80, rival);  // numerically lower
  deliver(r.backend_end, rival);                                      // the rival answers our claim
  std::string why;
  EXPECT_FALSE(backend.activate(2.0, &why));
  EXPECT_EQ(why,
            "cannot claim address 0x80: node with NAME 0x0000000000000001 has priority "
            "(craneassist's NAME 0x3000820000000C1A)");
  EXPECT_TRUE(backend.faulted());
  EXPECT_EQ(backend.fault_reason(), FaultReason::kAddressLost);
  EXPECT_EQ(backend.address_claim_state(), j1939::ClaimState::kLost);
  valves::MachineState state;
  // The control loop would go on calling write(); the watchdog and disable() run too.
  for (int k = 0; k < 5; ++k) {
    r.feedback();
    EXPECT_EQ(backend.read(state), valves::BackendStatus::kFault);
    EXPECT_FALSE(state.valid);
    backend.write(spool_command(0.5));
    std::this_thread::sleep_for(10ms);
  }
  std::this_thread::sleep_for(150ms);  // the watchdog: write() no longer called
  backend.disable();
  const auto sent = sent_by_backend(r.bus, r.map);
  ASSERT_GE(sent.size(), 2u);
  EXPECT_TRUE(is_claim(sent[0].frame, 0x80, kK70mName));
  EXPECT_TRUE(is_claim(sent[1].frame, j1939::kNullAddress, kK70mName));  // Cannot Claim
  int extension_blocks = 0;
  for (std::size_t i = 2; i < sent.size(); ++i) {
    EXPECT_FALSE(from_address(sent[i].frame, 0x80)) << hex(sent[i].frame);
    // The extension's driver takes an 11-bit frame, not from the address: it is held blocked.
    if (is_valve_frame(r.map.joints[3].valve, sent[i].frame)) {
      EXPECT_TRUE(is_block(r.map.joints[3], sent[i].frame));
      ++extension_blocks;
    }
  }
  EXPECT_GT(extension_blocks, 0);

  // A global request for address claimed is answered with Cannot Claim within 153 ms.
  r.bus.clear_log();
  CanFrame request;
  j1939::encode_request(j1939::kPgnAddressClaimed, 0x21, j1939::kGlobalAddress, request);
  r.sensors.send(request);
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < 200ms) {
    backend.read(state);
    std::this_thread::sleep_for(2ms);
  }
  int cannot_claim = 0;
  for (const auto& rx : sent_by_backend(r.bus, r.map)) {
    cannot_claim += is_claim(rx.frame, j1939::kNullAddress, kK70mName);
    EXPECT_FALSE(from_address(rx.frame, 0x80));
  }
  EXPECT_EQ(cannot_claim, 1);
}

TEST(CanBackendAddressClaim, WinsAgainstALowerPriorityNameAndReassertsItsClaim) {
  Rig r;
  r.map = claiming_mapping();
  CanBackend backend(r.map, r.cfg.model, r.backend_end);
  r.feedback();
  CanFrame rival;
  j1939::encode_address_claimed(0x5000000000000001ull, 0x80, rival);  // numerically higher
  deliver(r.backend_end, rival);
  std::string why;
  ASSERT_TRUE(backend.activate(2.0, &why)) << why;
  EXPECT_FALSE(backend.faulted());
  const auto sent = sent_by_backend(r.bus, r.map);
  ASSERT_GE(sent.size(), 2u);
  EXPECT_TRUE(is_claim(sent[0].frame, 0x80, kK70mName));
  EXPECT_TRUE(is_claim(sent[1].frame, 0x80, kK70mName));  // re-asserted against the rival
  EXPECT_EQ(backend.counters().claim_frames_sent, 2u);
  backend.write(spool_command(0.3));
  bool commanded = false;
  for (const auto& rx : sent_by_backend(r.bus, r.map)) {
    commanded = commanded || (rx.frame.id == 0x0CFE3080u && !is_block(r.map.joints[0], rx.frame));
  }
  EXPECT_TRUE(commanded);
}

TEST(CanBackendAddressClaim, AnswersRequestsAndDefendsItsAddressDuringOperation) {
  Rig r;
  r.map = claiming_mapping();
  CanBackend backend(r.map, r.cfg.model, r.backend_end);
  r.feedback();
  std::string why;
  ASSERT_TRUE(backend.activate(2.0, &why)) << why;
  valves::MachineState state;
  auto claims_after = [&](const CanFrame& incoming) {
    r.bus.clear_log();
    r.sensors.send(incoming);
    r.feedback();
    backend.read(state);
    int n = 0;
    for (const auto& rx : sent_by_backend(r.bus, r.map)) n += is_claim(rx.frame, 0x80, kK70mName);
    return n;
  };
  CanFrame f;
  j1939::encode_request(j1939::kPgnAddressClaimed, 0x21, j1939::kGlobalAddress, f);
  EXPECT_EQ(claims_after(f), 1);
  j1939::encode_request(j1939::kPgnAddressClaimed, 0x21, 0x80, f);
  EXPECT_EQ(claims_after(f), 1);
  j1939::encode_request(j1939::kPgnAddressClaimed, 0x21, 0x81, f);  // another node's
  EXPECT_EQ(claims_after(f), 0);
  j1939::encode_address_claimed(0x7000000000000000ull, 0x80, f);  // lower priority: defended
  EXPECT_EQ(claims_after(f), 1);
  j1939::encode_address_claimed(0x0000000000000001ull, 0x81, f);  // another address
  EXPECT_EQ(claims_after(f), 0);
  EXPECT_FALSE(backend.faulted());
  EXPECT_EQ(backend.counters().unknown_frames, 0u);  // network management is known

  // A node with priority takes the address while the valves move: fault, Cannot Claim, and
  // from then on nothing from 0x80 (commands, heartbeat, the watchdog's blocks).
  backend.write(spool_command(0.4));
  j1939::encode_address_claimed(0x0000000000000001ull, 0x80, f);
  r.sensors.send(f);
  r.bus.clear_log();  // from here on only what the backend sends
  EXPECT_EQ(backend.read(state), valves::BackendStatus::kFault);
  EXPECT_EQ(backend.fault_reason(), FaultReason::kAddressLost);
  EXPECT_EQ(backend.fault_text(),
            "address 0x80 lost: node with NAME 0x0000000000000001 claimed it with priority "
            "(craneassist's NAME 0x3000820000000C1A); nothing more is sent from it");
  for (int k = 0; k < 5; ++k) {
    backend.write(spool_command(0.4));
    std::this_thread::sleep_for(10ms);
  }
  std::this_thread::sleep_for(150ms);
  const auto sent = sent_by_backend(r.bus, r.map);
  ASSERT_FALSE(sent.empty());
  EXPECT_TRUE(is_claim(sent[0].frame, j1939::kNullAddress, kK70mName));
  for (const auto& rx : sent) EXPECT_FALSE(from_address(rx.frame, 0x80)) << hex(rx.frame);

  // The deliberate re-enable claims again (and loses again against the same rival).
  r.bus.clear_log();
  backend.enable();
  EXPECT_FALSE(backend.faulted());
  EXPECT_EQ(backend.address_claim_state(), j1939::ClaimState::kClaiming);
  backend.write(spool_command(0.4));  // still claiming: nothing but the claim
  const auto reclaim = sent_by_backend(r.bus, r.map);
  ASSERT_EQ(reclaim.size(), 1u);
  EXPECT_TRUE(is_claim(reclaim[0].frame, 0x80, kK70mName));
  r.sensors.send(f);
  EXPECT_EQ(backend.read(state), valves::BackendStatus::kFault);
  EXPECT_EQ(backend.fault_reason(), FaultReason::kAddressLost);
}

// ---- Valve supervision: the valves' replies and DM1 (docs/can.md, "Valve supervision") ----

// The K70M mapping with its valve replies (valves 0..2 from 0x20, the extension driver's status
// 0x211) and DM1 from 0x20, without the address claim.
CanMapping supervised_mapping() {
  CanMapping m = k70m_full_mapping();
  m.address_claim.reset();
  return m;
}

// What the valve group reports in one round.
struct ValveReport {
  iso11783::ValveState state = iso11783::ValveState::kBlock;  // of every AVC valve
  iso11783::LimitStatus limit = iso11783::LimitStatus::kNotLimited;
  std::uint8_t lift_only_limit = 0xFF;  // when set: the lift valve's limit status instead
  std::uint8_t driver_status = 0;       // the extension driver's status byte (0 ok)
  bool replies = true;                  // false: the valve group has fallen silent
};

struct SupervisedRig : Rig {
  CanBackend backend;
  valves::MachineState state;
  SupervisedRig() : Rig(), backend((map = supervised_mapping(), map), cfg.model, backend_end) {
    feedback();
    backend.read(state);
    backend.enable();
  }
  void replies(const ValveReport& report) {
    if (!report.replies) return;
    for (std::uint8_t v = 0; v < 3; ++v) {
      iso11783::AuxValveEstimatedFlow ef;
      ef.valve = v;
      ef.state = report.state;
      ef.fail_safe = iso11783::FailSafeMode::kBlock;
      ef.limit = v == 1 && report.lift_only_limit != 0xFF
                     ? static_cast<iso11783::LimitStatus>(report.lift_only_limit)
                     : report.limit;
      ef.extend_flow = ef.retract_flow = 0.0;
      CanFrame f;
      ASSERT_EQ(iso11783::encode(ef, 0x20, 3, f), iso11783::CodecStatus::kOk);
      sensors.send(f);
    }
    CanFrame st;
    st.id = 0x211;
    st.dlc = 1;
    st.data[0] = report.driver_status;
    sensors.send(st);
  }
  void dm1(const j1939::Dm1& d, std::uint8_t source = 0x20) {
    CanFrame f;
    j1939::encode_dm1(d, source, f);
    sensors.send(f);
  }
  // Control cycles at 100 Hz with fresh feedback and the given report, until the backend
  // faults or max_cycles pass. Returns the time from the first cycle to the fault.
  std::chrono::milliseconds run(const valves::ValveCommand& cmd, const ValveReport& report,
                                int max_cycles) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < max_cycles && !backend.faulted(); ++k) {
      feedback();
      replies(report);
      backend.read(state);
      backend.write(cmd);
      std::this_thread::sleep_until(t0 + (k + 1) * 10ms);
    }
    return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() -
                                                                 t0);
  }
  // The write() in the cycle of the fault blocked every section at once (the run's last
  // cycle): the latest command of each section on the bus is block, and stays so.
  void expect_every_section_blocked_now() {
    auto expect_last_block = [&] {
      bool seen[4] = {}, blocked[4] = {};
      for (const auto& rx : bus.log()) {
        for (std::size_t j = 0; j < 4; ++j) {
          if (!is_valve_frame(map.joints[j].valve, rx.frame)) continue;
          seen[j] = true;
          blocked[j] = is_block(map.joints[j], rx.frame);
        }
      }
      for (std::size_t j = 0; j < 4; ++j) EXPECT_TRUE(seen[j] && blocked[j]) << j;
    };
    expect_last_block();
    EXPECT_EQ(backend.read(state), valves::BackendStatus::kFault);
    EXPECT_FALSE(state.valid);
    std::this_thread::sleep_for(25ms);
    backend.write(spool_command(0.5));
    expect_last_block();
  }
};

ValveReport following(double spool) {
  ValveReport r;
  r.state = spool > 0   ? iso11783::ValveState::kExtend
            : spool < 0 ? iso11783::ValveState::kRetract
                        : iso11783::ValveState::kBlock;
  return r;
}

TEST(CanBackendSupervision, ValvesThatFollowAndAQuietDm1AreNormal) {
  SupervisedRig r;
  j1939::Dm1 quiet;  // lamps off, SPN 0: no active DTC
  r.dm1(quiet);
  r.run(spool_command(0.4), following(0.4), 50);  // 0.5 s, longer than the 300 ms timeouts
  EXPECT_FALSE(r.backend.faulted()) << r.backend.fault_text();
  // Commanded block, the valves report block: normal too (the valve echoes the command).
  r.run(spool_command(0.0), following(0.0), 40);
  // A small command inside a valve's dead band: a reported block is not held against it.
  r.run(spool_command(0.02), following(0.0), 40);
  EXPECT_FALSE(r.backend.faulted()) << r.backend.fault_text();
  const auto c = r.backend.counters();
  EXPECT_GT(c.valve_replies, 400u);
  EXPECT_EQ(c.dm1_messages, 1u);
  EXPECT_EQ(c.unknown_frames, 0u);
}

TEST(CanBackendSupervision, AValveReportingANonRecoverableFaultOrErrorStops) {
  {
    SupervisedRig r;
    r.run(spool_command(0.4), following(0.4), 10);
    ValveReport fault = following(0.4);
    fault.lift_only_limit = 6;  // non-recoverable fault
    r.run(spool_command(0.4), fault, 3);
    ASSERT_TRUE(r.backend.faulted());
    EXPECT_EQ(r.backend.fault_reason(), FaultReason::kValveFault);
    EXPECT_EQ(r.backend.fault_text(),
              "joint lift: valve 1 (0x20) reports a non-recoverable fault (limit status 6, state "
              "extend)");
    r.expect_every_section_blocked_now();
  }
  {
    SupervisedRig r;
    ValveReport error;
    error.state = iso11783::ValveState::kError;
    r.run(spool_command(0.0), error, 3);
    ASSERT_TRUE(r.backend.faulted());
    EXPECT_EQ(r.backend.fault_text(), "joint slew: valve 0 (0x20) reports error state");
  }
  {
    SupervisedRig r;  // the signal valve's driver: status 3 is not one of its ok values
    ValveReport status = following(0.0);
    status.driver_status = 3;
    r.run(spool_command(0.0), status, 3);
    ASSERT_TRUE(r.backend.faulted());
    EXPECT_EQ(r.backend.fault_reason(), FaultReason::kValveFault);
    EXPECT_EQ(r.backend.fault_text(),
              "joint extension: valve driver reports status 3 in frame 211 (not an ok value)");
  }
}

TEST(CanBackendSupervision, AValveInItsFailSafeWhileCommandedStopsAfterTheTimeout) {
  SupervisedRig r;
  r.run(spool_command(0.4), following(0.4), 10);
  // The valves fall back to block (their fail-safe) while craneassist commands 40 % extend.
  const auto took = r.run(spool_command(0.4), following(0.0), 60);
  ASSERT_TRUE(r.backend.faulted());
  EXPECT_EQ(r.backend.fault_reason(), FaultReason::kValveFault);
  EXPECT_NE(r.backend.fault_text().find("joint slew: valve 0 (0x20) reports fail-safe: state block "
                                        "for "),
            std::string::npos)
      << r.backend.fault_text();
  EXPECT_NE(r.backend.fault_text().find(" ms while commanded extend"), std::string::npos);
  EXPECT_GE(took, 300ms);
  EXPECT_LT(took, 450ms);  // the timeout, a reply period and a loaded host
  std::printf("valve in block while commanded extend: fault latched after %lld ms\n",
              static_cast<long long>(took.count()));
  r.expect_every_section_blocked_now();
  // Float is never commanded: a valve reporting float is in its fail-safe even while blocked.
  SupervisedRig f;
  ValveReport floating;
  floating.state = iso11783::ValveState::kFloat;
  f.run(spool_command(0.0), floating, 60);
  ASSERT_TRUE(f.backend.faulted());
  EXPECT_NE(f.backend.fault_text().find("reports fail-safe: state float"), std::string::npos)
      << f.backend.fault_text();
}

TEST(CanBackendSupervision, ARepliesThatStopOrNeverComeStopAfterTheTimeout) {
  {
    SupervisedRig r;
    r.run(spool_command(0.3), following(0.3), 20);
    ASSERT_FALSE(r.backend.faulted());
    ValveReport silent = following(0.3);
    silent.replies = false;
    const auto took = r.run(spool_command(0.3), silent, 60);
    ASSERT_TRUE(r.backend.faulted());
    EXPECT_EQ(r.backend.fault_reason(), FaultReason::kValveReplyLost);
    EXPECT_NE(r.backend.fault_text().find("joint slew: no valve reply for 3"), std::string::npos)
        << r.backend.fault_text();
    EXPECT_GE(took, 290ms);  // 300 ms after the last reply, which came up to a cycle earlier
    EXPECT_LT(took, 450ms);
    std::printf("valve replies stop: fault latched %lld ms after they stopped\n",
                static_cast<long long>(took.count()));
    r.expect_every_section_blocked_now();
  }
  {
    SupervisedRig r;  // no reply at all since enable()
    ValveReport silent;
    silent.replies = false;
    r.run(spool_command(0.0), silent, 60);
    ASSERT_TRUE(r.backend.faulted());
    EXPECT_EQ(r.backend.fault_text(), "joint slew: no valve reply within 300 ms of enable");
  }
}

TEST(CanBackendSupervision, Dm1WithAnActiveDtcOrTheRedStopLampStops) {
  {
    SupervisedRig r;
    r.run(spool_command(0.3), following(0.3), 5);
    j1939::Dm1 d;
    d.red_stop = j1939::Lamp::kOn;
    d.spn = 1234;
    d.fmi = 5;
    d.occurrence_count = 1;
    r.dm1(d);
    r.run(spool_command(0.3), following(0.3), 2);
    ASSERT_TRUE(r.backend.faulted());
    EXPECT_EQ(r.backend.fault_reason(), FaultReason::kDm1Fault);
    EXPECT_EQ(r.backend.fault_text(), "DM1 from 0x20: SPN 1234 FMI 5 (red stop lamp)");
    r.expect_every_section_blocked_now();
  }
  {
    SupervisedRig r;  // an active DTC with only the amber lamp: a stop as well
    j1939::Dm1 d;
    d.amber_warning = j1939::Lamp::kOn;
    d.spn = 520192;
    d.fmi = 31;
    r.dm1(d);
    r.run(spool_command(0.0), following(0.0), 2);
    EXPECT_EQ(r.backend.fault_text(), "DM1 from 0x20: SPN 520192 FMI 31 (amber warning lamp)");
  }
  {
    SupervisedRig r;  // the red stop lamp without a DTC
    j1939::Dm1 d;
    d.red_stop = j1939::Lamp::kOn;
    r.dm1(d);
    r.run(spool_command(0.0), following(0.0), 2);
    EXPECT_EQ(r.backend.fault_text(), "DM1 from 0x20: red stop lamp on, no DTC");
  }
  {
    SupervisedRig r;  // a multi-packet DM1 (3 DTCs) announced by TP.CM BAM
    CanFrame bam;
    bam.id = 0x1CECFF20;
    bam.extended = true;
    bam.dlc = 8;
    bam.data = {32, 14, 0, 2, 0xFF, 0xCA, 0xFE, 0x00};
    r.sensors.send(bam);
    r.run(spool_command(0.0), following(0.0), 2);
    EXPECT_EQ(r.backend.fault_text(),
              "DM1 from 0x20: 3 active DTCs (multi-packet DM1, its DTCs not decoded)");
  }
  {
    SupervisedRig r;  // another node's DM1 is not supervised; a malformed one of 0x20 is a fault
    j1939::Dm1 d;
    d.red_stop = j1939::Lamp::kOn;
    d.spn = 99;
    r.dm1(d, 0x33);
    r.run(spool_command(0.0), following(0.0), 3);
    EXPECT_FALSE(r.backend.faulted()) << r.backend.fault_text();
    EXPECT_EQ(r.backend.counters().unknown_frames, 1u);
    CanFrame shortdm1;
    j1939::encode_dm1(j1939::Dm1{}, 0x20, shortdm1);
    shortdm1.dlc = 3;
    r.sensors.send(shortdm1);
    r.run(spool_command(0.0), following(0.0), 2);
    EXPECT_EQ(r.backend.fault_reason(), FaultReason::kBadFeedbackFrame);
    EXPECT_EQ(r.backend.fault_text(),
              "DM1 from 0x20 with dlc 3: too short for the lamps and a DTC");
  }
}

TEST(CanBackendSupervision, ADm1FaultReportedBeforeEnableStopsRightAfterIt) {
  Rig r;
  r.map = supervised_mapping();
  CanBackend backend(r.map, r.cfg.model, r.backend_end);
  valves::MachineState state;
  j1939::Dm1 d;
  d.spn = 4321;
  d.fmi = 2;
  CanFrame f;
  j1939::encode_dm1(d, 0x20, f);
  r.sensors.send(f);
  r.feedback();
  backend.read(state);
  EXPECT_FALSE(backend.faulted());  // not enabled: not judged yet
  backend.enable();
  r.feedback();
  EXPECT_EQ(backend.read(state), valves::BackendStatus::kFault);
  EXPECT_EQ(backend.fault_text(), "DM1 from 0x20: SPN 4321 FMI 2 (no lamp on)");
}

// A transport that allocates nothing (the in-memory bus does): frames to receive are queued in a
// fixed array beforehand by the test thread, which also calls read(); sent frames are counted.
class StaticTransport final : public Transport {
 public:
  SendStatus send(const CanFrame&) override {
    sent.fetch_add(1);
    return SendStatus::kOk;
  }
  void receive(Received& out) override {
    if (head_ == tail_) {
      out.kind = ReceiveKind::kNone;
      return;
    }
    out = queue_[head_++ % queue_.size()];
  }
  bool wait_readable(int) override { return head_ != tail_; }
  const char* interface_name() const override { return "static0"; }
  void push(const CanFrame& f) {
    Received r;
    r.kind = ReceiveKind::kFrame;
    r.frame = f;
    r.timestamp_us = realtime_now_us();
    queue_[tail_++ % queue_.size()] = r;
  }
  std::atomic<int> sent{0};

 private:
  std::array<Received, 128> queue_{};
  std::size_t head_ = 0, tail_ = 0;
};

// The control thread's rule holds for the claim and the supervision: read() and write() allocate
// nothing while claiming, answering requests and contenders, judging replies and DM1, and
// latching a fault with its text.
TEST(CanBackendSupervision, ReadAndWriteDoNotAllocateWithClaimAndSupervision) {
  const CanMapping map = k70m_full_mapping();
  const auto cfg = config::default_crane_config();
  StaticTransport bus;
  CanBackend backend(map, cfg.model, bus);
  const double q[4] = {0.1, 0.2, -0.3, 1.0};
  std::vector<CanFrame> feedback;
  for (std::size_t i = 0; i < 4; ++i) {
    CanFrame f;
    f.id = map.joints[i].position.id;
    f.extended = map.joints[i].position.extended;
    f.dlc = required_dlc(map.joints[i].position);
    ASSERT_EQ(encode(map.joints[i].position, q[i], f), SignalStatus::kOk);
    feedback.push_back(f);
  }
  std::vector<CanFrame> replies;
  for (std::uint8_t v = 0; v < 3; ++v) {
    iso11783::AuxValveEstimatedFlow ef;
    ef.valve = v;
    ef.state = iso11783::ValveState::kExtend;
    ef.limit = iso11783::LimitStatus::kNotLimited;
    CanFrame f;
    ASSERT_EQ(iso11783::encode(ef, 0x20, 3, f), iso11783::CodecStatus::kOk);
    replies.push_back(f);
  }
  CanFrame status;
  status.id = 0x211;
  status.dlc = 1;
  replies.push_back(status);
  CanFrame request, rival, quiet_dm1, bad_dm1;
  j1939::encode_request(j1939::kPgnAddressClaimed, 0x21, j1939::kGlobalAddress, request);
  j1939::encode_address_claimed(0x7000000000000000ull, 0x80, rival);
  j1939::encode_dm1(j1939::Dm1{}, 0x20, quiet_dm1);
  j1939::Dm1 d;
  d.red_stop = j1939::Lamp::kOn;
  d.spn = 1234;
  d.fmi = 5;
  j1939::encode_dm1(d, 0x20, bad_dm1);
  const auto cmd = spool_command(0.3);
  valves::MachineState state;
  for (const auto& f : feedback) bus.push(f);
  backend.read(state);  // sizes the state's vectors
  backend.enable();     // starts the claim

  auto cycle = [&](std::initializer_list<const CanFrame*> extra) {
    for (const auto& f : feedback) bus.push(f);
    for (const auto& f : replies) bus.push(f);
    for (const CanFrame* f : extra) bus.push(*f);
    const long before = test::heap_allocations();
    backend.read(state);
    backend.write(cmd);
    return test::heap_allocations() - before;
  };
  EXPECT_EQ(cycle({&request, &rival, &quiet_dm1}), 0) << "claiming";
  EXPECT_EQ(backend.address_claim_state(), j1939::ClaimState::kClaiming);
  for (int k = 0; k < 30 && backend.address_claim_state() != j1939::ClaimState::kClaimed; ++k) {
    cycle({});
    std::this_thread::sleep_for(10ms);
  }
  ASSERT_EQ(backend.address_claim_state(), j1939::ClaimState::kClaimed);
  const int sent_before = bus.sent.load();
  EXPECT_EQ(cycle({&request, &quiet_dm1}), 0) << "claimed, commanding";
  EXPECT_GT(bus.sent.load(), sent_before);
  EXPECT_FALSE(backend.faulted()) << backend.fault_text();
  EXPECT_EQ(cycle({&bad_dm1}), 0) << "latching a fault";
  EXPECT_TRUE(backend.faulted());
  EXPECT_EQ(backend.fault_text(), "DM1 from 0x20: SPN 1234 FMI 5 (red stop lamp)");
}

}  // namespace
}  // namespace craneassist::can
