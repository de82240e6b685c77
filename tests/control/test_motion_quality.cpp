// control::MotionQuality on synthetic runs: what counts as a stall, what as lateral speed.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "craneassist/control/motion_quality.hpp"

using craneassist::control::MotionQuality;
using craneassist::control::MotionQualityResult;

namespace {

constexpr double kPeriod = 0.01;

// Drives a tip along: speed(t) along command(t), plus a lateral velocity lateral(t).
MotionQualityResult run(const std::function<Eigen::Vector3d(double)>& command,
                        const std::function<double(double)>& speed_share,
                        const std::function<Eigen::Vector3d(double)>& lateral, double duration) {
  MotionQuality q(kPeriod);
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();
  for (int k = 0; k * kPeriod < duration; ++k) {
    const double t = k * kPeriod;
    const Eigen::Vector3d c = command(t);
    const Eigen::Vector3d v =
        (c.allFinite() ? Eigen::Vector3d(c * speed_share(t)) : Eigen::Vector3d::Zero()) +
        lateral(t);
    tip += v * kPeriod;
    q.add(t, c, tip, v);
  }
  return q.result();
}

const auto kOut = [](double) { return Eigen::Vector3d(0.6, 0.0, 0.0); };
const auto kNoLateral = [](double) { return Eigen::Vector3d::Zero(); };

}  // namespace

TEST(MotionQuality, ASlowDownAndRecoveryWithTheStickUnchangedIsAStall) {
  auto share = [](double t) { return t < 1.0 ? t : (t > 4.0 && t < 5.0 ? 0.05 : 1.0); };
  const auto r = run(kOut, share, kNoLateral, 8.0);
  EXPECT_EQ(r.stall_events, 1);
  EXPECT_TRUE(r.one_line);
}

TEST(MotionQuality, StoppingAtTheEdgeIsNotAStall) {
  auto share = [](double t) { return t < 1.0 ? t : (t > 4.0 ? 0.0 : 1.0); };
  EXPECT_EQ(run(kOut, share, kNoLateral, 8.0).stall_events, 0);
}

TEST(MotionQuality, ASlowDownThatDoesNotRecoverToSeventyPerCentIsNotAStall) {
  auto share = [](double t) {
    return t < 1.0 ? t : (t > 4.0 && t < 5.0 ? 0.05 : t > 5 ? 0.6 : 1.0);
  };
  EXPECT_EQ(run(kOut, share, kNoLateral, 8.0).stall_events, 0);
}

TEST(MotionQuality, SlowingBecauseTheStickMovedIsNotAStall) {
  auto command = [](double t) {
    return t < 4.0 ? Eigen::Vector3d(0.6, 0, 0) : Eigen::Vector3d(0.6001, 0, 0);
  };
  // The speed dips exactly when the stick moves and recovers under the new stick position.
  auto share = [](double t) { return t < 1.0 ? t : (t > 3.5 && t < 4.5 ? 0.05 : 1.0); };
  EXPECT_EQ(run(command, share, kNoLateral, 8.0).stall_events, 0);
}

TEST(MotionQuality, TwoStallsCountTwice) {
  auto share = [](double t) {
    return t < 1.0 ? t : ((t > 3.0 && t < 3.5) || (t > 5.0 && t < 5.5) ? 0.1 : 1.0);
  };
  EXPECT_EQ(run(kOut, share, kNoLateral, 8.0).stall_events, 2);
}

TEST(MotionQuality, LateralSpeedIsMeasuredAcrossTheLineOverFiftyMilliseconds) {
  // 0.02 m/s sideways for 0.3 s, and a one-cycle 0.5 mm bounce.
  auto lateral = [](double t) {
    Eigen::Vector3d l = Eigen::Vector3d::Zero();
    if (t > 2.0 && t < 2.3) l.y() = 0.02;
    if (std::abs(t - 3.0) < 0.001) l.z() = 0.05;
    return l;
  };
  auto reversing = [](double t) {
    return t < 2.5 ? Eigen::Vector3d(0.6, 0, 0) : Eigen::Vector3d(-0.6, 0, 0);
  };
  const auto r = run(
      reversing, [](double) { return 1.0; }, lateral, 5.0);
  ASSERT_TRUE(r.one_line);
  EXPECT_NEAR(r.lateral_peak_m_s, 0.02, 1e-9);
  EXPECT_NEAR(r.lateral_peak_cycle_m_s, 0.05, 1e-9);
  EXPECT_NEAR(r.line.x(), 1.0, 1e-12);
}

TEST(MotionQuality, CommandsOffTheLineHaveNoLateralFigure) {
  auto turning = [](double t) {
    return t < 2.0 ? Eigen::Vector3d(0.6, 0, 0) : Eigen::Vector3d(0, 0.6, 0);
  };
  const auto r = run(
      turning, [](double) { return 1.0; }, kNoLateral, 4.0);
  EXPECT_FALSE(r.one_line);
  EXPECT_EQ(r.lateral_peak_m_s, 0.0);
}

TEST(MotionQuality, InvalidInputRowsAreNeitherStallsNorOffTheLine) {
  auto command = [](double t) {
    return t > 3.0 && t < 3.5 ? Eigen::Vector3d(NAN, NAN, NAN) : Eigen::Vector3d(0.6, 0, 0);
  };
  auto share = [](double t) { return t < 1.0 ? t : 1.0; };
  const auto r = run(command, share, kNoLateral, 6.0);
  EXPECT_EQ(r.stall_events, 0);
  EXPECT_TRUE(r.one_line);
}
