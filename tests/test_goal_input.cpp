// GoalInput (app/control/goal_input.hpp): following a published tip plan, the handoff between a
// producer thread and the control thread, and its ends.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>
#include <vector>

#include "craneassist/control/goal_input.hpp"

namespace {

using craneassist::control::CycleTime;
using craneassist::control::GoalInput;
using craneassist::control::GoalInputSettings;
using craneassist::control::TipCommand;
using craneassist::control::TipSample;

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

CycleTime at(double t) {
  CycleTime c;
  c.t_s = t;
  c.now_s = t;
  return c;
}

TEST(GoalInput, NoCommandBeforeAPlan) {
  GoalInput input(GoalInputSettings{.capacity = 16});
  TipCommand cmd;
  input.next(at(0.0), Eigen::Vector3d(1, 2, 0), cmd);
  EXPECT_FALSE(cmd.v_m_s.allFinite());
  EXPECT_STREQ(cmd.reason, "no goal");
  Eigen::Vector3d tip;
  double t = -1;
  ASSERT_TRUE(input.last_tip(tip, t));
  EXPECT_EQ(tip, Eigen::Vector3d(1, 2, 0));
  EXPECT_EQ(t, 0.0);
}

TEST(GoalInput, RejectsBadPlans) {
  GoalInput input(GoalInputSettings{.capacity = 4});
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

// A tip that moves as commanded follows the plan and stops at the goal.
TEST(GoalInput, FollowsThePlanAndStopsAtTheGoal) {
  GoalInput input(GoalInputSettings{.capacity = 256, .position_gain_1_s = 2.0});
  const Eigen::Vector3d a(3, 1, 0), b(5, 2, 0);
  ASSERT_TRUE(input.publish(straight(a, b, 4.0, 101), 1.0));
  Eigen::Vector3d tip = a + Eigen::Vector3d(0.05, 0, 0);  // starts off the plan
  TipCommand cmd;
  const double dt = 0.01;
  double worst_late = 0.0, t = 0.0;
  bool reached = false;
  for (int k = 0; k < 1000 && !reached; ++k) {
    t = k * dt;
    input.next(at(t), tip, cmd);
    if (!cmd.v_m_s.allFinite()) {
      reached = std::string(cmd.reason) == "goal reached";
      continue;
    }
    if (t > 2.5) worst_late = std::max(worst_late, (input.reference() - tip).norm());
    tip += cmd.v_m_s * dt;
  }
  ASSERT_TRUE(reached);
  EXPECT_TRUE(input.reached());
  EXPECT_GE(t, 5.0);  // not before the plan's end
  EXPECT_LT((tip - b).norm(), 0.02);
  EXPECT_LT(worst_late, 0.01);  // once the start offset is worked off, on the plan
}

// The feedback part is capped: a tip far off is pulled back at the cap, plus the plan's speed.
TEST(GoalInput, FeedbackSpeedIsCapped) {
  GoalInput input(GoalInputSettings{.capacity = 16, .feedback_speed_cap_m_s = 0.3});
  ASSERT_TRUE(input.publish(straight({0, 0, 0}, {1, 0, 0}, 1.0, 3), 0.0));
  TipCommand cmd;
  input.next(at(5.0), Eigen::Vector3d(1, 10, 0), cmd);  // after the end, 10 m off
  ASSERT_TRUE(cmd.v_m_s.allFinite());
  EXPECT_NEAR(cmd.v_m_s.norm(), 0.3, 1e-12);
  EXPECT_NEAR(cmd.v_m_s.y(), -0.3, 1e-12);
  // Without a measured tip: no command.
  input.next(at(5.01), Eigen::Vector3d::Constant(NAN), cmd);
  EXPECT_FALSE(cmd.v_m_s.allFinite());
}

// A producer publishing new plans while the control thread reads them: every plan the control
// thread sees is whole (its samples all belong to one publication).
TEST(GoalInput, HandoffUnderContentionDeliversWholePlans) {
  GoalInput input(GoalInputSettings{.capacity = 512});
  std::atomic<bool> done{false};
  std::thread producer([&] {
    for (int k = 1; k <= 400; ++k) {
      const double x = k;  // every sample of plan k lies on x = k
      std::vector<TipSample> plan;
      for (int i = 0; i < 512; ++i)
        plan.push_back({0.001 * i, Eigen::Vector3d(x, 0.001 * i, 0), Eigen::Vector3d::Zero()});
      ASSERT_TRUE(input.publish(plan, 0.0));
    }
    done = true;
  });
  TipCommand cmd;
  int seen = 0;
  double last_x = 0.0;
  for (int k = 0; !done || k < 10; ++k) {
    input.next(at(0.0001 * (k % 5000)), Eigen::Vector3d(0, 0, 0), cmd);
    if (!input.has_plan()) continue;
    const double x = input.reference().x();
    EXPECT_EQ(x, std::round(x));
    EXPECT_GE(x, last_x);  // never an older plan after a newer one
    last_x = x;
    ++seen;
  }
  producer.join();
  input.next(at(0.0), Eigen::Vector3d(0, 0, 0), cmd);
  EXPECT_EQ(input.reference().x(), 400.0);  // the last plan arrives
  EXPECT_GT(seen, 0);
  EXPECT_GE(input.plans_taken(), 1u);
}

}  // namespace
