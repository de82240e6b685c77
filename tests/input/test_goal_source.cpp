// GoalSource (input/goal_source.hpp): following a published tip plan, the handoff between a
// producer thread and the control thread, and its ends.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>
#include <vector>

#include "craneassist/input/goal_source.hpp"

namespace {

using craneassist::input::GoalSource;
using craneassist::input::GoalSourceSettings;
using craneassist::input::OperatorCommand;
using craneassist::input::SourceState;
using craneassist::input::TipSample;

// A straight move from a to b in `duration` with a smooth (cosine) speed profile.
std::vector<TipSample> straight(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double duration,
                                int n) {
  std::vector<TipSample> out;
  for (int k = 0; k < n; ++k) {
    const double t = duration * k / (n - 1), u = t / duration;
    const double s = 0.5 - 0.5 * std::cos(M_PI * u),
                 ds = 0.5 * M_PI * std::sin(M_PI * u) / duration;
    out.push_back({t, a + s * (b - a), ds * (b - a)});
  }
  return out;
}

// One cycle at loop time t with the tip measured there: the source's command (NaN when it gives
// none: no data, or the deadman released).
Eigen::Vector3d command(GoalSource& source, double t, const Eigen::Vector3d& tip) {
  source.begin_cycle(t, tip);
  OperatorCommand cmd;
  if (source.poll(cmd) != SourceState::kOk || !cmd.deadman) return Eigen::Vector3d::Constant(NAN);
  EXPECT_EQ(cmd.stamp_s, t);
  return cmd.v_m_s;
}

TEST(GoalSource, NoCommandBeforeAPlan) {
  GoalSource input(GoalSourceSettings{.capacity = 16});
  input.begin_cycle(0.0, Eigen::Vector3d(1, 2, 0));
  OperatorCommand cmd;
  EXPECT_EQ(input.poll(cmd), SourceState::kNoData);
  EXPECT_STREQ(input.state(), "no goal");
  Eigen::Vector3d tip;
  double t = -1;
  ASSERT_TRUE(input.last_tip(tip, t));
  EXPECT_EQ(tip, Eigen::Vector3d(1, 2, 0));
  EXPECT_EQ(t, 0.0);
}

TEST(GoalSource, RejectsBadPlans) {
  GoalSource input(GoalSourceSettings{.capacity = 4});
  const auto plan = straight({0, 0, 0}, {1, 0, 0}, 1.0, 5);
  EXPECT_FALSE(input.publish(plan, 0.0));  // over capacity
  auto bad = straight({0, 0, 0}, {1, 0, 0}, 1.0, 4);
  bad[2].t_s = bad[1].t_s;
  EXPECT_FALSE(input.publish(bad, 0.0));
  bad = straight({0, 0, 0}, {1, 0, 0}, 1.0, 4);
  bad[1].p_m.x() = NAN;
  EXPECT_FALSE(input.publish(bad, 0.0));
  EXPECT_FALSE(input.publish({}, 0.0));
  EXPECT_FALSE(input.publish(straight({0, 0, 0}, {1, 0, 0}, 1.0, 4), NAN));
}

// A tip that moves as commanded follows the plan and stops at the goal. Before it moves, the
// source arms the input monitor: one cycle released, then arming_s held with no motion; the
// plan's clock starts after that.
TEST(GoalSource, FollowsThePlanAndStopsAtTheGoal) {
  GoalSource input(GoalSourceSettings{.capacity = 256, .position_gain_1_s = 2.0, .arming_s = 0.3});
  const Eigen::Vector3d a(3, 1, 0), b(5, 2, 0);
  ASSERT_TRUE(input.publish(straight(a, b, 4.0, 101), 0.0));
  Eigen::Vector3d tip = a + Eigen::Vector3d(0.05, 0, 0);  // starts off the plan
  const double dt = 0.01;
  double worst_late = 0.0, t = 0.0, first_following = -1.0;
  int arming_held = 0;
  bool reached = false;
  for (int k = 0; k < 1000 && !reached; ++k) {
    t = k * dt;
    const Eigen::Vector3d v = command(input, t, tip);
    if (!v.allFinite()) {
      reached = std::string(input.state()) == "goal reached";
      if (k == 0) {
        EXPECT_STREQ(input.state(), "arming");  // released: the deadman's press comes next
      }
      continue;
    }
    if (std::string(input.state()) == "arming") {
      EXPECT_EQ(v, Eigen::Vector3d::Zero());
      ++arming_held;
      continue;
    }
    EXPECT_STREQ(input.state(), "following");
    if (first_following < 0.0) {
      first_following = t;
      EXPECT_LT((input.reference() - a).norm(), 1e-12);  // the plan starts now, at its start
    }
    if (t > first_following + 1.5) {
      worst_late = std::max(worst_late, (input.reference() - tip).norm());
    }
    tip += v * dt;
  }
  EXPECT_NEAR(arming_held * dt, 0.3, 0.011);
  ASSERT_TRUE(reached);
  EXPECT_TRUE(input.reached());
  EXPECT_GE(t, first_following + 4.0);  // not before the plan's end
  EXPECT_LT((tip - b).norm(), 0.02);
  EXPECT_LT(worst_late, 0.01);  // once the start offset is worked off, on the plan
}

// The feedback part is capped: a tip far off is pulled back at the cap, plus the plan's speed.
TEST(GoalSource, FeedbackSpeedIsCapped) {
  GoalSource input(
      GoalSourceSettings{.capacity = 16, .feedback_speed_cap_m_s = 0.3, .arming_s = 0.0});
  ASSERT_TRUE(input.publish(straight({0, 0, 0}, {1, 0, 0}, 1.0, 3), 0.0));
  EXPECT_FALSE(command(input, 4.99, Eigen::Vector3d(0, 10, 0)).allFinite());  // arming
  // The plan starts now (no arming hold), at (0, 0, 0) at rest; the tip is 10 m above it.
  const Eigen::Vector3d v = command(input, 5.0, Eigen::Vector3d(0, 10, 0));
  ASSERT_TRUE(v.allFinite());
  EXPECT_NEAR(v.norm(), 0.3, 1e-12);
  EXPECT_NEAR(v.y(), -0.3, 1e-12);
  // Without a measured tip: no command.
  EXPECT_FALSE(command(input, 5.01, Eigen::Vector3d::Constant(NAN)).allFinite());
  EXPECT_STREQ(input.state(), "no tip measurement");
}

// A producer publishing new plans while the control thread reads them: every plan the control
// thread sees is whole (its samples all belong to one publication) and never older than the one
// before. Every tenth plan the producer waits until the control thread has taken a plan, so the
// two threads interleave even on a loaded machine; the others race.
TEST(GoalSource, HandoffUnderContentionDeliversWholePlans) {
  GoalSource input(GoalSourceSettings{.capacity = 512});
  std::atomic<bool> done{false};
  std::thread producer([&] {
    for (int k = 1; k <= 400; ++k) {
      const double x = k;  // every sample of plan k lies on x = k
      std::vector<TipSample> plan;
      for (int i = 0; i < 512; ++i) {
        plan.push_back({0.001 * i, Eigen::Vector3d(x, 0.001 * i, 0), Eigen::Vector3d::Zero()});
      }
      const auto taken = input.plans_taken();
      EXPECT_TRUE(input.publish(plan, 0.0));
      if (k % 10 == 0) {
        while (input.plans_taken() == taken) std::this_thread::yield();
      }
    }
    done = true;
  });
  int seen = 0;
  double last_x = 0.0;
  for (int k = 0; !done; ++k) {
    command(input, 0.0001 * (k % 5000), Eigen::Vector3d(0, 0, 0));
    if (!input.has_plan()) continue;
    const double x = input.reference().x();
    EXPECT_NEAR(x, std::round(x), 1e-9);
    EXPECT_GE(std::round(x), last_x);  // never an older plan after a newer one
    last_x = std::round(x);
    ++seen;
  }
  producer.join();
  command(input, 0.0, Eigen::Vector3d(0, 0, 0));
  EXPECT_NEAR(input.reference().x(), 400.0, 1e-9);  // the last plan arrives
  EXPECT_GT(seen, 0);
  EXPECT_GE(input.plans_taken(), 40u);
}

}  // namespace
