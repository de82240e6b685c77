// The input monitor: every fault stops (zero command) and says why; motion resumes only after
// the deadman is released and pressed again.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "allocation_counter.hpp"
#include "craneassist/input/input_monitor.hpp"

using namespace craneassist::input;

namespace {

struct Harness {
  InputMonitor monitor{InputMonitorSettings{0.1, 2.0}};
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
};

const Eigen::Vector3d kMove(0.3, 0.0, 0.0);

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
  h.step(kMove, false);
  EXPECT_TRUE(h.step(kMove, true).enabled);
}

TEST(InputMonitor, StaleInputStopsAndNeedsReArm) {
  Harness h;
  h.step(kMove, false);
  ASSERT_TRUE(h.step(kMove, true).enabled);
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
  h.step(kMove, false);
  EXPECT_TRUE(h.step(kMove, true).enabled);
}

TEST(InputMonitor, ReleaseDuringTheFaultDoesNotCount) {
  Harness h;
  h.step(kMove, false);
  ASSERT_TRUE(h.step(kMove, true).enabled);
  h.step(kMove, false, SourceState::kOk, 0.5);  // stale sample, deadman released: not trusted
  EXPECT_EQ(h.step(kMove, true).fault, InputFault::kNotArmed);
}

TEST(InputMonitor, NonFiniteAndOutOfRangeCommandsStop) {
  Harness h;
  h.step(kMove, false);
  ASSERT_TRUE(h.step(kMove, true).enabled);
  auto o = h.step({NAN, 0.0, 0.0}, true);
  EXPECT_EQ(o.fault, InputFault::kNotFinite);
  EXPECT_TRUE(o.v_m_s.allFinite() && o.v_m_s.isZero());
  h.step(kMove, false);
  ASSERT_TRUE(h.step(kMove, true).enabled);
  o = h.step({0.0, -2.5, 0.0}, true);
  EXPECT_EQ(o.fault, InputFault::kOutOfRange);
  EXPECT_TRUE(o.v_m_s.isZero());
  o = h.step({0.0, 0.0, INFINITY}, true);
  EXPECT_EQ(o.fault, InputFault::kNotFinite);
  // A NaN stamp is stale.
  h.step(kMove, false);
  ASSERT_TRUE(h.step(kMove, true).enabled);
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
  h.step(kMove, false);
  ASSERT_TRUE(h.step(kMove, true).enabled);
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
  h.step(kMove, false);
  EXPECT_TRUE(h.step(kMove, true).enabled);
}

TEST(InputMonitor, UpdateAllocatesNothing) {
  Harness h;
  const long before = craneassist::test::heap_allocations();
  for (int i = 0; i < 1000; ++i) h.step(kMove, i % 7 != 0, SourceState::kOk, (i % 13) * 0.01);
  EXPECT_EQ(craneassist::test::heap_allocations(), before);
}
