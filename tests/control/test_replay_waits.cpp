// A replay's wait rows (docs/replay-format.md#waits) on the simulated K70M: the run holds a wait
// row until the grapple has settled, every later row comes that much later, and the summary gives
// the waits and the cycle time. What a user tries: a push and a wait, damped and undamped; a crane
// whose grapple does not hang; a wait that cannot end; a wait on the last row.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/replay_runner.hpp"
#include "craneassist/dynamics/pendulum.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

using namespace craneassist;

namespace {

// Each cycle's command and swing, as the loop saw them.
struct Probe final : control::CycleObserver {
  struct Sample {
    double t, cmd_x, swing_deg, tip_speed;
  };
  std::vector<Sample> samples;
  Probe() { samples.reserve(20000); }
  void on_cycle(const control::CycleRecord& c) noexcept override {
    const auto& r = c.row;
    samples.push_back({r.t, r.cmd[0], std::abs(c.state.swing_rad) * 180.0 / M_PI,
                       std::hypot(r.tip_v[0], r.tip_v[1], r.tip_v[2])});
  }
  // The first time from which the command's x is `x` (NaN: never).
  double first(double x, double after = 0.0) const {
    for (const auto& s : samples) {
      if (s.t >= after && s.cmd_x == x) return s.t;
    }
    return NAN;
  }
};

struct WaitRun {
  control::RunSummary summary;
  Probe probe;
};

// Out at 0.6 m/s for 2.5 s, released with a wait, then in at 0.3 m/s from 3.5 s for 1 s. (Not
// 2 s: that is about one swing period with 400 kg, and the undamped stop then happens to cancel
// the swing the undamped start left.)
const char* kPushAndWait =
    "t,v_x,v_y,v_z,wait\n"
    "0,0.6,0,0,0\n"
    "2.5,0,0,0,1\n"
    "3.5,-0.3,0,0,0\n"
    "4.5,0,0,0,0\n";

WaitRun run(config::CraneConfig cfg, const char* replay_text, bool damped,
            control::WaitSettings waits = {}, double settle_s = 1.0) {
  cfg.scaling.sway_damping = damped;
  // From the sway study's pose (docs/sway.md), so the load stays well inside the chart.
  cfg.simulation.q_initial = config::parse_joint_pose(
      cfg.model, "lift=35 deg, tilt=-110 deg, extension=1.8 m", cfg.simulation.q_initial);
  const auto replay = input::Replay::parse(replay_text, "waits.csv");
  sim_backend::SimBackend machine(cfg.model, offline::sim_settings(cfg));
  WaitRun r;
  control::RunOptions options;
  options.waits = waits;
  options.settle_s = settle_s;
  options.observers.push_back(&r.probe);
  r.summary = control::run_replay(cfg, replay, machine, options, nullptr);
  return r;
}

config::CraneConfig k70m(double payload_kg) {
  auto cfg = config::default_crane_config();
  config::set_payload_mass(cfg.model, payload_kg);
  return cfg;
}

}  // namespace

TEST(ReplayWaits, AWaitHoldsTheReplayUntilTheGrappleHasSettledAndShiftsTheRowsAfterIt) {
  const auto cfg = k70m(400.0);
  const auto waits = control::wait_settings(cfg);
  // The window is one period of the slowest swing the config allows (the heaviest load).
  EXPECT_NEAR(waits.window_s, dynamics::grapple_pendulum(cfg.model, 1e5).period_s(), 1e-12);
  EXPECT_GT(waits.window_s, 1.7);
  for (const bool damped : {true, false}) {
    SCOPED_TRACE(damped ? "damped" : "undamped");
    const WaitRun r = run(cfg, kPushAndWait, damped, waits);
    const auto& w = r.summary.waits;
    ASSERT_EQ(w.waits, 1);
    // Undamped, the 400 kg log swings on under the link's brake past the timeout.
    EXPECT_EQ(w.timed_out, damped ? 0 : 1);
    EXPECT_GT(w.total_s, waits.window_s);
    EXPECT_EQ(w.longest_s, w.total_s);
    // The row after the wait comes that much later than its time in the file (to a cycle).
    const double back = r.probe.first(-0.3);
    EXPECT_NEAR(back, 3.5 + w.total_s, 0.011);
    EXPECT_NEAR(r.summary.cycle_time_s, 4.5 + w.total_s, 1e-9);
    // And it came only once the swing had stayed within the bound for the window, the tip at
    // rest.
    for (const auto& s : r.probe.samples) {
      if (w.timed_out > 0 || s.t < back - waits.window_s || s.t >= back) continue;
      EXPECT_LE(s.swing_deg, waits.swing_rad * 180.0 / M_PI + 1e-9) << s.t;
      EXPECT_LE(s.tip_speed, waits.rest_speed_m_s) << s.t;
    }
    // The run went on for the settle time after the shifted last row (then its end stop).
    EXPECT_NEAR(r.summary.duration_s - 0.01 * static_cast<double>(r.summary.stop_cycles),
                4.5 + w.total_s + 1.0, 0.021);
  }
  // Damping the swing is what shortens the wait.
  const auto damped = run(cfg, kPushAndWait, true, waits).summary.waits;
  const auto undamped = run(cfg, kPushAndWait, false, waits).summary.waits;
  std::printf(
      "[ figures  ] push out at 0.6 m/s with 400 kg and a wait: %.2f s damped, %.2f s "
      "undamped (%ld timed out)\n",
      damped.total_s, undamped.total_s, undamped.timed_out);
  EXPECT_LT(damped.total_s, 5.0);
  EXPECT_LT(damped.total_s, 0.5 * undamped.total_s);
}

TEST(ReplayWaits, WithoutASwingMeasurementTheWaitIsForTheTipAtRest) {
  auto cfg = k70m(0.0);
  cfg.model.grapple = dynamics::HangingGrapple{};  // rigid at the tip: nothing measures a swing
  const WaitRun r = run(cfg, kPushAndWait, true, control::wait_settings(cfg));
  ASSERT_EQ(r.summary.waits.waits, 1);
  EXPECT_EQ(r.summary.waits.timed_out, 0);
  EXPECT_TRUE(std::isnan(r.summary.waits.residual_swing_deg));
  // The stop and 0.5 s at rest (the window without a swing).
  EXPECT_GT(r.summary.waits.total_s, 0.5);
  EXPECT_LT(r.summary.waits.total_s, 2.5);
}

TEST(ReplayWaits, AWaitThatCannotEndTimesOutAndTheReplayGoesOn) {
  auto waits = control::wait_settings(k70m(400.0), 1e-6);  // a bound no swing stays within
  waits.timeout_s = 1.5;
  const WaitRun r = run(k70m(400.0), kPushAndWait, false, waits);
  EXPECT_EQ(r.summary.waits.waits, 1);
  EXPECT_EQ(r.summary.waits.timed_out, 1);
  EXPECT_NEAR(r.summary.waits.total_s, 1.5, 0.011);
  EXPECT_NEAR(r.probe.first(-0.3), 3.5 + 1.5, 0.021);
}

TEST(ReplayWaits, AWaitOnTheLastRowExtendsTheRun) {
  const char* text =
      "t,v_x,v_y,v_z,wait\n"
      "0,0.6,0,0,0\n"
      "2,0,0,0,1\n";
  const auto cfg = k70m(400.0);
  const WaitRun r = run(cfg, text, true, control::wait_settings(cfg), 0.5);
  ASSERT_EQ(r.summary.waits.waits, 1);
  EXPECT_EQ(r.summary.waits.timed_out, 0);
  EXPECT_NEAR(r.summary.duration_s - 0.01 * static_cast<double>(r.summary.stop_cycles),
              2.0 + r.summary.waits.total_s + 0.5, 0.021);
  EXPECT_LT(r.probe.samples.back().swing_deg, 2.0);
}

TEST(ReplayWaits, AReplayWithoutWaitsRunsAsBefore) {
  const char* text =
      "t,v_x,v_y,v_z\n"
      "0,0.6,0,0\n"
      "2,0,0,0\n";
  const WaitRun r = run(k70m(0.0), text, true);
  EXPECT_EQ(r.summary.waits.waits, 0);
  EXPECT_EQ(r.summary.cycle_time_s, 2.0);
  EXPECT_EQ(r.summary.cycles - r.summary.stop_cycles, 301);  // 3 s at 100 Hz, then its end stop
}
