// The input monitor: every fault stops (zero command) and says why; motion resumes only after
// the deadman is released and pressed again, has been held for deadman_hold and the stop has
// lasted stop_latch; a chattering deadman never lets the command through.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "allocation_counter.hpp"
#include "craneassist/input/input_monitor.hpp"

using namespace craneassist::input;

namespace {

const Eigen::Vector3d kMove(0.3, 0.0, 0.0);

// The fault rules alone (deadman_hold and stop_latch 0: the press that arms passes at once);
// TimedHarness has the shipped timing rules.
struct Harness {
  explicit Harness(const InputMonitorSettings& settings = {0.1, 2.0, 0.0, 0.0})
      : monitor(settings) {}
  InputMonitor monitor;
  MonitorOutput out;
  double now = 10.0;

  // One cycle 10 ms later with a fresh sample.
  MonitorOutput step(const Eigen::Vector3d& v, bool deadman, SourceState state = SourceState::kOk,
                     double age_s = 0.0) {
    now += 0.01;
    OperatorCommand c;
    c.stamp_s = now - age_s;
    c.v_m_s = v;
    c.deadman = deadman;
    monitor.update(state, c, now, out);
    return out;
  }

  // The deadman released for a cycle, then pressed: the pressed cycle's output.
  MonitorOutput release_and_press() {
    step(kMove, false);
    return step(kMove, true);
  }
};

}  // namespace

TEST(InputMonitor, ArmsOnAFreshPressAndPassesTheCommand) {
  Harness h;
  auto o = h.step(kMove, false);
  EXPECT_FALSE(o.enabled);
  EXPECT_EQ(o.fault, InputFault::kDeadmanReleased);
  EXPECT_TRUE(o.v_m_s.isZero());
  o = h.step(kMove, true);
  EXPECT_TRUE(o.enabled);
  EXPECT_EQ(o.fault, InputFault::kNone);
  EXPECT_EQ(o.v_m_s, kMove);
  EXPECT_STREQ(to_string(o.fault), "");
}

TEST(InputMonitor, DeadmanHeldSinceStartupDoesNotArm) {
  Harness h;
  for (int i = 0; i < 5; ++i) {
    const auto o = h.step(kMove, true);
    EXPECT_FALSE(o.enabled);
    EXPECT_EQ(o.fault, InputFault::kNotArmed);
    EXPECT_TRUE(o.v_m_s.isZero());
  }
  EXPECT_TRUE(h.release_and_press().enabled);
}

TEST(InputMonitor, StaleInputStopsAndNeedsReArm) {
  Harness h;
  ASSERT_TRUE(h.release_and_press().enabled);
  EXPECT_TRUE(h.step(kMove, true, SourceState::kOk, 0.099).enabled);
  auto o = h.step(kMove, true, SourceState::kOk, 0.112);
  EXPECT_FALSE(o.enabled);
  EXPECT_EQ(o.fault, InputFault::kStale);
  EXPECT_STREQ(to_string(o.fault), "input stale");
  EXPECT_NEAR(o.input_age_s, 0.112, 1e-9);
  EXPECT_TRUE(o.v_m_s.isZero());
  // Fresh again with the deadman still held: no motion until released and pressed.
  o = h.step(kMove, true);
  EXPECT_FALSE(o.enabled);
  EXPECT_EQ(o.fault, InputFault::kNotArmed);
  EXPECT_TRUE(h.release_and_press().enabled);
}

TEST(InputMonitor, ReleaseDuringTheFaultDoesNotCount) {
  Harness h;
  ASSERT_TRUE(h.release_and_press().enabled);
  h.step(kMove, false, SourceState::kOk, 0.5);  // stale sample, deadman released: not trusted
  EXPECT_EQ(h.step(kMove, true).fault, InputFault::kNotArmed);
}

TEST(InputMonitor, NonFiniteAndOutOfRangeCommandsStop) {
  Harness h;
  ASSERT_TRUE(h.release_and_press().enabled);
  auto o = h.step({NAN, 0.0, 0.0}, true);
  EXPECT_EQ(o.fault, InputFault::kNotFinite);
  EXPECT_TRUE(o.v_m_s.allFinite() && o.v_m_s.isZero());
  ASSERT_TRUE(h.release_and_press().enabled);
  o = h.step({0.0, -2.5, 0.0}, true);
  EXPECT_EQ(o.fault, InputFault::kOutOfRange);
  EXPECT_TRUE(o.v_m_s.isZero());
  o = h.step({0.0, 0.0, INFINITY}, true);
  EXPECT_EQ(o.fault, InputFault::kNotFinite);
  // A NaN stamp is stale.
  ASSERT_TRUE(h.release_and_press().enabled);
  OperatorCommand c;
  c.stamp_s = NAN;
  c.v_m_s = kMove;
  c.deadman = true;
  h.monitor.update(SourceState::kOk, c, h.now + 0.01, h.out);
  EXPECT_EQ(h.out.fault, InputFault::kStale);
}

TEST(InputMonitor, DisconnectAndReattachAreCountedAndNeedReArm) {
  Harness h;
  auto o = h.step(kMove, true, SourceState::kDisconnected);  // absent at start: no event
  EXPECT_EQ(o.fault, InputFault::kDisconnected);
  EXPECT_EQ(h.monitor.disconnects(), 0);
  ASSERT_TRUE(h.release_and_press().enabled);
  o = h.step(kMove, true, SourceState::kDisconnected);
  EXPECT_FALSE(o.enabled);
  EXPECT_STREQ(to_string(o.fault), "device disconnected");
  EXPECT_FALSE(o.deadman);
  h.step(kMove, true, SourceState::kDisconnected);
  EXPECT_EQ(h.monitor.disconnects(), 1);
  o = h.step(kMove, true, SourceState::kNoData);
  EXPECT_EQ(o.fault, InputFault::kNoData);
  EXPECT_EQ(h.monitor.reconnects(), 1);
  EXPECT_EQ(h.step(kMove, true).fault, InputFault::kNotArmed);
  EXPECT_TRUE(h.release_and_press().enabled);
}

TEST(InputMonitor, UpdateAllocatesNothing) {
  Harness h;
  const long before = craneassist::test::heap_allocations();
  for (int i = 0; i < 1000; ++i) h.step(kMove, i % 7 != 0, SourceState::kOk, (i % 13) * 0.01);
  EXPECT_EQ(craneassist::test::heap_allocations(), before);
}

// The defaults: the deadman held 0.3 s, the stop latched 1 s.
struct TimedHarness : Harness {
  TimedHarness() : Harness(InputMonitorSettings{}) {}
  // `n` cycles of 10 ms with the deadman as given; how many passed the command.
  int run(int n, bool deadman, const Eigen::Vector3d& v = kMove) {
    int passed = 0;
    for (int i = 0; i < n; ++i) passed += step(v, deadman).enabled ? 1 : 0;
    return passed;
  }
  // Held from now on: the command passes after the hold time (0.3 s), not before.
  void expect_passes_after_the_hold() {
    EXPECT_EQ(run(30, true), 0);
    EXPECT_TRUE(step(kMove, true).enabled);
  }
  // Released for 50 ms, then held past the hold time (0.31 s): whether the command passes now
  // (it should).
  bool arm() {
    run(5, false);
    run(31, true);
    return out.enabled;
  }
};

TEST(InputMonitor, TheDefaultsHoldTheDeadmanAndLatchTheStop) {
  const InputMonitorSettings d;
  EXPECT_DOUBLE_EQ(d.deadman_hold_s, 0.3);
  EXPECT_DOUBLE_EQ(d.stop_latch_s, 1.0);
}

TEST(InputMonitor, TheCommandPassesOnlyAfterTheDeadmanIsHeldForTheHoldTime) {
  TimedHarness h;
  h.run(5, false);
  // 0.29 s held: arming; from 0.30 s on it passes.
  for (int i = 0; i < 30; ++i) {
    const auto o = h.step(kMove, true);
    EXPECT_FALSE(o.enabled) << i;
    EXPECT_EQ(o.fault, InputFault::kArming) << i;
    EXPECT_TRUE(o.v_m_s.isZero());
  }
  EXPECT_STREQ(to_string(InputFault::kArming), "arming: keep the deadman held");
  const auto o = h.step(kMove, true);
  EXPECT_TRUE(o.enabled);
  EXPECT_EQ(o.v_m_s, kMove);
  // A release during the hold starts it again.
  TimedHarness g;
  g.run(5, false);
  EXPECT_EQ(g.run(20, true), 0);
  g.run(1, false);
  g.expect_passes_after_the_hold();
}

TEST(InputMonitor, AReleaseLatchesTheStop) {
  TimedHarness h;
  ASSERT_TRUE(h.arm());
  // Released for one cycle, pressed again at once: stopped for 1 s from the release.
  EXPECT_EQ(h.run(1, false), 0);
  int latched = 0;
  for (int i = 0; i < 99; ++i) {
    const auto o = h.step(kMove, true);
    EXPECT_FALSE(o.enabled) << i;
    latched += o.fault == InputFault::kStopLatched ? 1 : 0;
  }
  EXPECT_EQ(latched, 99);  // the latch (1 s) outlasts the hold (0.3 s) and is what is shown
  EXPECT_STREQ(to_string(InputFault::kStopLatched), "stop latched");
  EXPECT_TRUE(h.step(kMove, true).enabled);
  // Released longer than the latch: only the hold delays the command.
  h.run(150, false);
  h.expect_passes_after_the_hold();
}

TEST(InputMonitor, AFaultLatchesTheStopToo) {
  TimedHarness h;
  ASSERT_TRUE(h.arm());
  EXPECT_EQ(h.step(kMove, true, SourceState::kOk, 0.2).fault, InputFault::kStale);
  h.run(1, false);  // re-arm at once
  int passed = 0;
  for (int i = 0; i < 98; ++i) passed += h.step(kMove, true).enabled ? 1 : 0;
  EXPECT_EQ(passed, 0);
  EXPECT_EQ(h.out.fault, InputFault::kStopLatched);
  EXPECT_TRUE(h.step(kMove, true).enabled);
}

// A deadman that chatters (pressed and released in turn, every cycle or every few cycles) never
// lets the command through after the first release, however long it goes on.
TEST(InputMonitor, AChatteringDeadmanKeepsTheCommandStopped) {
  for (int period : {1, 2, 5, 29}) {
    TimedHarness h;
    ASSERT_TRUE(h.arm());
    int passed = 0;
    for (int i = 0; i < 1000; ++i) {
      passed += h.step(kMove, (i / period) % 2 == 1).enabled ? 1 : 0;
    }
    EXPECT_EQ(passed, 0) << "chatter every " << period << " cycles";
    EXPECT_FALSE(h.monitor.armed() && h.out.enabled);
  }
  // Held for longer than the hold between releases: the latch keeps the stop 1 s after each,
  // so the command passes in at most a few short bursts.
  TimedHarness h;
  h.arm();
  int passed = 0;
  for (int i = 0; i < 1000; ++i) passed += h.step(kMove, i % 40 != 0).enabled ? 1 : 0;
  EXPECT_LT(passed, 1000 / 10);
}

TEST(InputMonitor, ZeroHoldAndLatchArmAtThePress) {
  Harness h;  // 0 and 0: the monitor before the timing rules
  ASSERT_TRUE(h.release_and_press().enabled);
  EXPECT_TRUE(h.release_and_press().enabled);
}

TEST(InputMonitor, DriveStickPassesWithTheCommandAndIsCheckedLikeIt) {
  Harness h;
  h.step(kMove, false);
  OperatorCommand c;
  c.v_m_s = kMove;
  c.deadman = true;
  c.drive = Eigen::Vector2d(0.5, -0.25);
  h.now += 0.01;
  c.stamp_s = h.now;
  h.monitor.update(SourceState::kOk, c, h.now, h.out);
  EXPECT_TRUE(h.out.enabled);
  EXPECT_EQ(h.out.drive, c.drive);
  // Released deadman: no drive either.
  c.deadman = false;
  h.now += 0.01;
  c.stamp_s = h.now;
  h.monitor.update(SourceState::kOk, c, h.now, h.out);
  EXPECT_TRUE(h.out.drive.isZero());
  // A drive outside the stick's travel, or not finite, is a fault like the tip command's.
  for (const double bad : {1.5, std::nan("")}) {
    h.release_and_press();
    c.deadman = true;
    c.drive = Eigen::Vector2d(bad, 0.0);
    h.now += 0.01;
    c.stamp_s = h.now;
    h.monitor.update(SourceState::kOk, c, h.now, h.out);
    EXPECT_FALSE(h.out.enabled) << bad;
    EXPECT_EQ(h.out.fault, std::isnan(bad) ? InputFault::kNotFinite : InputFault::kOutOfRange);
    EXPECT_TRUE(h.out.drive.isZero());
  }
}
