// Every stop ends with the machine at rest, and gently (docs/safety.md): on the simulated K70M,
// a 0.6 m/s push ended by the replay's end, a stop row, a released deadman and a stop request
// (SIGINT, q) each leave the measured tip below 0.01 m/s when the valves go neutral, no spool
// command moves more than the slew-rate limit from one cycle to the next, and no section is
// driven fully open against the side it moved when the stop began. The same with simulated
// spools twice as fast and twice as slow as the controller's model, and then the tip does not
// come back along its path (no overshoot). The dead-band lead never commands more than the
// wanted opening plus the dead band's width.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/live_loop.hpp"
#include "craneassist/control/replay_runner.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/input/command_source.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"
#include "craneassist/valves/proportional_valves.hpp"
#include "craneassist/valves/reference_follower.hpp"

using namespace craneassist;

namespace {

constexpr double kPushS = 3.0;  // the push's length: the tip is at 0.6 m/s when it ends
const Eigen::Vector3d kPush(0.6, 0.0, 0.0);

// Every row of a run.
class Rows : public control::CycleObserver {
 public:
  Rows() { rows.reserve(2000); }
  void on_cycle(const control::CycleRecord& c) noexcept override {
    if (rows.size() < rows.capacity()) rows.push_back(c.row);
  }
  std::vector<control::LogRow> rows;
};

// The operator pushes out, then lets go of the deadman (or the stop flag is set) at kPushS.
class Operator : public input::CommandSource {
 public:
  Operator(bool release_deadman, std::atomic<bool>* stop)
      : release_(release_deadman), stop_(stop) {}
  void begin_cycle(double now_s, const Eigen::Vector3d&) noexcept override { now_ = now_s; }
  input::SourceState poll(input::OperatorCommand& out) noexcept override {
    out.stamp_s = now_;
    out.v_m_s = kPush;
    out.deadman = now_ >= 0.1 && !(release_ && now_ >= kPushS);  // pressed after start-up
    if (stop_ != nullptr && now_ >= kPushS) stop_->store(true);
    return input::SourceState::kOk;
  }
  const char* name() const noexcept override { return "scripted"; }

 private:
  bool release_;
  std::atomic<bool>* stop_;
  double now_ = 0.0;
};

struct Ending {
  const char* name;
  control::StopSummary stop;
  double peak_spool_step = 0.0;
  std::vector<control::LogRow> rows;
};

// The K70M with its simulated spools' time constant (negative: the model's).
config::CraneConfig crane(double spool_time_constant_s) {
  auto cfg = config::default_crane_config();
  if (spool_time_constant_s >= 0.0) {
    for (auto& v : cfg.simulation.valves) v.time_constant_s = spool_time_constant_s;
  }
  return cfg;
}

Ending by_replay(const config::CraneConfig& cfg, const char* name, const std::string& text) {
  const auto replay = input::Replay::parse(text, name);
  sim_backend::SimBackend sim(cfg.model, offline::sim_settings(cfg));
  Rows rows;
  control::RunOptions options;
  options.settle_s = 0.0;
  options.observers = {&rows};
  const auto s = control::run_replay(cfg, replay, sim, options, nullptr);
  return {name, s.stop, s.peak_spool_step, rows.rows};
}

Ending by_operator(const config::CraneConfig& cfg, const char* name, bool deadman) {
  std::atomic<bool> stop{false};
  Operator op(deadman, deadman ? nullptr : &stop);
  sim_backend::SimBackend sim(cfg.model, offline::sim_settings(cfg));
  Rows rows;
  control::LiveOptions options;
  options.realtime = false;
  options.duration_s = kPushS + 5.0;
  options.stop = &stop;
  options.monitor.deadman_hold_s = 0.0;
  options.observers = {&rows};
  const auto s = control::run_live(cfg, op, sim, options, nullptr);
  return {name, s.stop, s.peak_spool_step, rows.rows};
}

std::vector<Ending> every_ending(const config::CraneConfig& cfg) {
  const std::string push = "t,v_x,v_y,v_z\n0,0.6,0,0\n3,0.6,0,0\n";
  return {by_replay(cfg, "replay end", push),
          by_replay(cfg, "stop row", "t,v_x,v_y,v_z,stop\n0,0.6,0,0,0\n3,0,0,0,1\n6,0,0,0,1\n"),
          by_operator(cfg, "deadman release", true), by_operator(cfg, "stop request", false)};
}

double speed(const control::LogRow& r) {
  return std::sqrt(r.tip_v[0] * r.tip_v[0] + r.tip_v[1] * r.tip_v[1] + r.tip_v[2] * r.tip_v[2]);
}

// The ending's checks.
void expect_gentle_stop_at_rest(const config::CraneConfig& cfg, const Ending& e) {
  SCOPED_TRACE(e.name);
  const double bound = valves::max_spool_step(cfg.model.valves, 1.0 / cfg.control.rate_hz);
  EXPECT_GE(e.stop.stops, 1);
  EXPECT_EQ(e.stop.end, control::StopEnd::kAtRest);
  EXPECT_LT(e.stop.tip_speed_at_neutral_m_s, 0.01);
  EXPECT_EQ(e.stop.timeouts, 0);
  EXPECT_EQ(e.stop.full_reverse_cycles, 0);
  EXPECT_LE(e.peak_spool_step, bound + 1e-12);
  // The rows say the same: the first stopped row's measured tip, and the steps.
  std::size_t first_stopped = e.rows.size();
  for (std::size_t k = 0; k < e.rows.size(); ++k) {
    if (std::string(e.rows[k].status) == "stopped") {
      first_stopped = k;
      break;
    }
  }
  ASSERT_LT(first_stopped, e.rows.size());
  EXPECT_LT(speed(e.rows[first_stopped]), 0.01) << "t " << e.rows[first_stopped].t;
  for (std::size_t k = 1; k < e.rows.size(); ++k) {
    for (int j = 0; j < cfg.model.dof(); ++j) {
      ASSERT_LE(std::abs(e.rows[k].spool[j] - e.rows[k - 1].spool[j]), bound + 1e-12)
          << "t " << e.rows[k].t << " section " << j + 1;
    }
  }
  // No overshoot: once stopping, the tip never comes back along the push by more than 2 mm.
  double furthest = -1e9;
  bool stopping = false;
  for (const auto& r : e.rows) {
    stopping = stopping || std::string(r.status) != "running";
    if (!stopping || !std::isfinite(r.tip[0])) continue;
    furthest = std::max(furthest, r.tip[0]);
    EXPECT_GT(r.tip[0], furthest - 0.002) << "t " << r.t;
  }
}

}  // namespace

TEST(StopAtRest, EveryRunEndLeavesTheCraneAtRestBeforeTheValvesGoNeutral) {
  const auto cfg = crane(-1.0);
  ASSERT_GT(cfg.model.valves.stroke_time_s, 0.0);
  for (const auto& e : every_ending(cfg)) {
    expect_gentle_stop_at_rest(cfg, e);
    EXPECT_LT(e.stop.time_s, 2.5) << e.name;
  }
}

TEST(StopAtRest, FasterAndSlowerSpoolsThanTheModelStopWithoutOvershootOrKick) {
  for (const double factor : {0.5, 2.0}) {
    const auto cfg = crane(factor * config::default_crane_config().model.valves.time_constant_s);
    SCOPED_TRACE("spool time constant " + std::to_string(cfg.simulation.valves[0].time_constant_s));
    expect_gentle_stop_at_rest(
        cfg, by_replay(cfg, "replay end", "t,v_x,v_y,v_z\n0,0.6,0,0\n3,0.6,0,0\n"));
  }
}

TEST(StopAtRest, ALoadThatKeepsMovingIsReportedAfterTheRestTimeout) {
  // A rest speed no sensor could resolve: the settling runs out of time and says so; the valves
  // still go neutral, ramped.
  auto cfg = crane(-1.0);
  cfg.control.rest_speed_m_s = 1e-12;
  cfg.control.rest_timeout_s = 0.5;
  const auto e = by_replay(cfg, "replay end", "t,v_x,v_y,v_z\n0,0.6,0,0\n3,0.6,0,0\n");
  EXPECT_EQ(e.stop.end, control::StopEnd::kTimeout);
  EXPECT_EQ(e.stop.timeouts, 1);
  EXPECT_STREQ(e.rows.back().status, "stopped");
}

// The lead through the dead band: from rest, and when the wanted side changes (a feedback
// correction, a reversal), the command never exceeds the wanted one plus the dead band's width
// (plus the way back to neutral while the spool is on the other side), moves at most the
// slew-rate limit per cycle, never carries the model's spool past the wanted position, and ends
// at the wanted command.
TEST(ReferenceFollower, TheDeadBandLeadStaysWithinTheWantedOpeningPlusTheDeadBand) {
  const auto cfg = config::default_crane_config();
  const auto& model = cfg.model;
  const double period = 1.0 / cfg.control.rate_hz;
  valves::ReferenceFollower follower(model, 0.0, period);
  valves::ProportionalValves dzi(model, 0.0);
  follower.reset(cfg.simulation.q_initial);
  const int n = model.dof();
  dynamics::JointVector q = cfg.simulation.q_initial, qdot = dynamics::JointVector::Zero(n);
  dynamics::JointVector arms(n);
  valves::ValveCommand out, wanted;
  valves::ProportionalValvesInput in{dynamics::JointVector::Zero(n),
                                     dynamics::JointVector::Zero(n)};
  const double band = model.valves.dead_zone;
  std::vector<double> last(static_cast<std::size_t>(n), 0.0);
  // Lift slowly up, then slowly down (a flip across the band), then fast, then stop.
  const std::vector<std::pair<double, double>> phases{
      {0.02, 30}, {-0.02, 30}, {0.3, 30}, {0.0, 30}};
  for (const auto& [rate, cycles] : phases) {
    for (int k = 0; k < cycles; ++k) {
      qdot.setZero();
      qdot[1] = rate;
      dynamics::cylinder_arms(model, q, arms);
      for (int i = 0; i < n; ++i) in.velocity_ref_m_s[i] = arms[i] * qdot[i];
      dzi.update(in, wanted);
      std::vector<double> estimate(static_cast<std::size_t>(n));
      for (int i = 0; i < n; ++i)
        estimate[static_cast<std::size_t>(i)] = follower.spool_estimate(i);
      follower.update(q, qdot, nullptr, out);
      for (int i = 0; i < n; ++i) {
        const double w = wanted.spool[i];
        const double u = out.spool[i];
        EXPECT_LE(std::abs(u - last[static_cast<std::size_t>(i)]), follower.max_step() + 1e-12);
        if (w != 0.0) {
          // The dead band's width, and the way back to neutral from the other side.
          const double back =
              std::max(0.0, -std::copysign(1.0, w) * estimate[static_cast<std::size_t>(i)]);
          EXPECT_LE(std::abs(u), std::abs(w) + band + back + 1e-12)
              << "rate " << rate << " k " << k;
          EXPECT_LE(std::copysign(1.0, w) * follower.spool_estimate(i), std::abs(w) + 1e-9)
              << "the model's spool past the wanted position, rate " << rate << " k " << k;
        }
        last[static_cast<std::size_t>(i)] = u;
      }
    }
    // Each phase ends at the wanted command.
    EXPECT_NEAR(out.spool[1], wanted.spool[1], 1e-9) << "rate " << rate;
  }
}
