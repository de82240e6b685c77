// The live loop on the simulated crane with scripted operators: a recorded session replays to
// the same log byte for byte (faults included, as stop rows), every input fault gives a
// jerk-limited stop with its reason and then neutral valves, motion resumes in the commanded
// direction only after a re-arm, a chattering deadman keeps the crane stopped, and the loop
// allocates nothing per cycle. Also measures the times from the last fresh input to the stop
// command, to the tip at rest and to neutral valves.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "allocation_counter.hpp"
#include "craneassist/config/base_config.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/live_loop.hpp"
#include "craneassist/control/replay_runner.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/sim_backend/mobile_crane_backend.hpp"
#include "csv_cells.hpp"

using namespace craneassist;

namespace {

// What the scripted operator does at machine time t.
struct Script {
  input::SourceState state = input::SourceState::kOk;
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  bool deadman = true;
  bool fresh = true;  // false: the sample keeps its old stamp (a frozen device)
  Eigen::Vector2d drive = Eigen::Vector2d::Zero();  // the drive stick (sim --drive)
};

class ScriptedSource : public input::CommandSource {
 public:
  explicit ScriptedSource(std::function<Script(double)> script) : script_(std::move(script)) {}
  void begin_cycle(double now_s, const Eigen::Vector3d&) noexcept override { now_ = now_s; }
  input::SourceState poll(input::OperatorCommand& out) noexcept override {
    const Script s = script_(now_);
    if (s.state != input::SourceState::kOk) return s.state;
    if (s.fresh) {
      out.stamp_s = now_;
      out.v_m_s = s.v;
      out.deadman = s.deadman;
      out.drive = s.drive;
    }
    return s.state;
  }
  const char* name() const noexcept override { return "scripted"; }

 private:
  std::function<Script(double)> script_;
  double now_ = 0.0;
};

// Keeps every row (preallocated) and the heap allocations seen at each cycle.
class Probe : public control::CycleObserver {
 public:
  explicit Probe(std::size_t n) {
    rows.reserve(n);
    allocations.reserve(n);
  }
  void on_cycle(const control::CycleRecord& cycle) noexcept override {
    const control::LogRow& row = cycle.row;
    if (rows.size() < rows.capacity()) {
      rows.push_back(row);
      allocations.push_back(craneassist::test::heap_allocations());
    }
  }
  std::vector<control::LogRow> rows;
  std::vector<long> allocations;
};

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

double speed(const control::LogRow& r) {
  return std::sqrt(r.tip_v[0] * r.tip_v[0] + r.tip_v[1] * r.tip_v[1] + r.tip_v[2] * r.tip_v[2]);
}

const Eigen::Vector3d kOut(0.4, 0.0, 0.0);

// Moves out with the deadman pressed after start-up (released for the first 0.1 s).
Script moving(double t) {
  Script s;
  s.v = kOut;
  s.deadman = t >= 0.1;
  return s;
}

control::LiveOptions scripted_options(double duration_s, Probe* probe) {
  control::LiveOptions o;
  o.realtime = false;
  o.duration_s = duration_s;
  if (probe != nullptr) o.observers.push_back(probe);
  return o;
}

}  // namespace

TEST(LiveLoop, RecordedSessionReplaysToTheSameLog) {
  const auto cfg = config::default_crane_config();
  // A session with every kind of interruption: moves, a deadman release and re-press, a frozen
  // device, a NaN, a disconnect, a change of direction.
  ScriptedSource source([](double t) {
    Script s;
    s.deadman = t >= 0.05;
    s.v = t < 1.5 ? Eigen::Vector3d(0.3, 0.2, 0.0) : Eigen::Vector3d(-0.2, 0.0, 0.3);
    if (t >= 0.8 && t < 1.0) s.deadman = false;
    if (t >= 1.0 && t < 1.1) s.v = Eigen::Vector3d(0.25, 0.1, -0.1);
    if (t >= 2.0 && t < 2.3) s.fresh = false;
    if (t >= 2.5 && t < 2.52) s.v.x() = NAN;
    if (t >= 2.6 && t < 2.8) s.deadman = false;
    if (t >= 3.0 && t < 3.3) s.state = input::SourceState::kDisconnected;
    if (t >= 3.4 && t < 3.5) s.deadman = false;
    return s;
  });
  const auto dir = std::filesystem::temp_directory_path();
  const auto live_log = dir / "craneassist_live_session.csv";
  const auto replay_log = dir / "craneassist_live_replayed.csv";
  std::vector<input::ReplayRow> record;
  control::LiveSummary live;
  {
    sim_backend::SimBackend machine(cfg.model, offline::sim_settings(cfg));
    control::CsvLog log(live_log, cfg.model.dof());
    auto options = scripted_options(4.5, nullptr);
    // The monitor's timing rules off (deadman hold, stop latch; tested below), so that each
    // scripted interruption stays an interval of its own in the recording.
    options.monitor.deadman_hold_s = 0.0;
    options.monitor.stop_latch_s = 0.0;
    options.record = &record;
    live = control::run_live(cfg, source, machine, options, &log);
  }
  // 4.5 s of session, then the end of the run's jerk-limited stop (the crane was moving).
  EXPECT_GT(live.cycles, 470);
  EXPECT_LT(live.cycles, 650);
  EXPECT_EQ(live.disconnects, 1);
  EXPECT_EQ(live.reconnects, 1);
  EXPECT_GT(live.enabled_cycles, 200);
  EXPECT_LT(live.enabled_cycles, 400);
  ASSERT_GE(record.size(), 8u);
  EXPECT_EQ(record.front().t_s, 0.0);
  EXPECT_NEAR(record.back().t_s, 4.49, 1e-12);
  // The faults are stop rows with a zero velocity; the file gets the stop column.
  int stop_rows = 0;
  for (const auto& r : record) {
    stop_rows += r.stop;
    if (r.stop) {
      EXPECT_TRUE(r.v_m_s.isZero(0.0));
    }
  }
  // Start-up, the deadman release, stale + NaN + deadman (no re-arm between them), disconnect
  // + deadman.
  EXPECT_EQ(stop_rows, 4);

  // Through the file format and the replay command's loop.
  std::stringstream text;
  input::write_replay(text, record);
  EXPECT_TRUE(text.str().starts_with("t,v_x,v_y,v_z,stop\n"));
  const auto replay = input::Replay::parse(text.str(), "recording");
  {
    sim_backend::SimBackend machine(cfg.model, offline::sim_settings(cfg));
    control::CsvLog log(replay_log, cfg.model.dof());
    control::RunOptions options;
    options.settle_s = 0.0;
    const auto summary = control::run_replay(cfg, replay, machine, options, &log);
    EXPECT_EQ(summary.cycles, live.cycles) << "the replay ends with the same stop";
  }
  const std::string a = read_file(live_log), b = read_file(replay_log);
  EXPECT_GT(a.size(), 100000u);
  EXPECT_TRUE(a == b) << "the replayed log differs from the live log";
  // The log holds the fault intervals (the cmd columns hold nan): the crane stops, and once the
  // reference is at rest every spool is exactly 0.
  std::istringstream lines(a);
  std::string line;
  std::getline(lines, line);
  const std::vector<std::string> header = test::csv_cells(line);
  auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    EXPECT_NE(it, header.end()) << name;
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::size_t cmd_vx = column("cmd_vx"), sdot = column("sdot"), spool1 = column("spool1"),
                    status = column("status");
  int nan_rows = 0, at_rest_rows = 0, stopped_rows = 0, neutral_rows = 0;
  while (std::getline(lines, line)) {
    const std::vector<std::string> f = test::csv_cells(line);
    if (f[cmd_vx] != "nan") continue;
    ++nan_rows;
    if (std::stod(f[sdot]) != 0.0) continue;
    ++at_rest_rows;  // the reference at rest: the machine settles, then the valves go neutral
    if (f[status] != "stopped") continue;
    ++stopped_rows;
    bool neutral = true;
    for (std::size_t i = spool1; i < spool1 + 4; ++i) neutral = neutral && f[i] == "0.00000";
    neutral_rows += neutral;
  }
  EXPECT_GT(nan_rows, 80);
  EXPECT_GE(stopped_rows, 1);  // the short interruptions end before the crane settles
  EXPECT_GE(at_rest_rows, stopped_rows);
  EXPECT_EQ(neutral_rows, stopped_rows) << "stopped in a fault, every valve is neutral";
}

TEST(LiveLoop, StaleInputStopsJerkLimitedAndMotionResumesOnlyAfterReArm) {
  const auto cfg = config::default_crane_config();
  const double t_freeze = 2.0;  // the last fresh sample
  ScriptedSource source([&](double t) {
    Script s = moving(t);
    if (t > t_freeze && t < 4.0) s.fresh = false;  // device frozen
    if (t >= 5.0 && t < 5.2) s.deadman = false;    // the operator re-arms
    return s;
  });
  sim_backend::SimBackend machine(cfg.model, offline::sim_settings(cfg));
  Probe probe(800);
  control::run_live(cfg, source, machine, scripted_options(7.0, &probe), nullptr);
  ASSERT_GE(probe.rows.size(), 700u) << "7 s, then the end of the run's stop";

  // Moving before the freeze.
  const auto& before = probe.rows[195];
  EXPECT_STREQ(before.status, "running");
  EXPECT_GT(speed(before), 0.3);
  EXPECT_TRUE(before.deadman);
  EXPECT_STREQ(before.input_source, "scripted");

  double t_stop_cmd = -1.0, t_rest = -1.0, t_neutral = -1.0;
  double peak_jerk = 0.0;
  bool saw_stopping = false;
  for (const auto& r : probe.rows) {
    if (r.t <= t_freeze) continue;
    if (t_stop_cmd < 0.0 && std::string(r.stop_reason) == "input stale") {
      t_stop_cmd = r.t;
      EXPECT_TRUE(std::isnan(r.cmd[0]));  // the controller's stale_input stop
      EXPECT_STREQ(r.active_limit, "stale_input");
    }
    if (t_stop_cmd >= 0.0 && r.t < 4.0) {
      peak_jerk = std::max(peak_jerk, std::abs(r.sdddot));
      saw_stopping = saw_stopping || std::string(r.status) == "stopping";
      if (t_rest < 0.0 && speed(r) < 1e-3) t_rest = r.t;
      if (t_neutral < 0.0 && std::string(r.status) == "stopped") {
        t_neutral = r.t;
        for (int i = 0; i < 4; ++i) EXPECT_EQ(r.spool[static_cast<std::size_t>(i)], 0.0);
      }
    }
  }
  ASSERT_GT(t_stop_cmd, 0.0);
  ASSERT_GT(t_rest, 0.0);
  ASSERT_GT(t_neutral, 0.0);
  const double detect_ms = (t_stop_cmd - t_freeze) * 1e3;
  const double rest_ms = (t_rest - t_freeze) * 1e3;
  const double neutral_ms = (t_neutral - t_freeze) * 1e3;
  std::printf(
      "[ figures  ] from the last fresh input (0.4 m/s out): stop commanded after %.0f ms "
      "(timeout 100 ms), tip below 1 mm/s after %.0f ms, valves neutral after %.0f ms, peak "
      "path jerk %.2f m/s^3\n",
      detect_ms, rest_ms, neutral_ms, peak_jerk);
  EXPECT_GT(detect_ms, 100.0 - 1e-6);
  EXPECT_LE(detect_ms, 110.0 + 1e-6);  // the timeout plus at most one cycle
  EXPECT_LT(rest_ms, 1500.0);
  EXPECT_LT(neutral_ms, 1500.0);
  EXPECT_TRUE(saw_stopping);
  EXPECT_LE(peak_jerk, cfg.scaling.jerk_max_m_s3 + 1e-9);
  // Stopped with every valve exactly neutral, from then on until the re-arm at 5.2 s and the
  // deadman held 0.3 s: while stale, fresh again at 4 s but not re-armed, with the deadman
  // released, and arming.
  const auto neutral_k = static_cast<std::size_t>(std::lround(t_neutral * 100.0));
  for (std::size_t k = neutral_k; k < 550; ++k) {
    const auto& r = probe.rows[k];
    EXPECT_STREQ(r.status, "stopped") << "t " << r.t;
    EXPECT_TRUE(std::isnan(r.cmd[0])) << "t " << r.t;
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(r.spool[static_cast<std::size_t>(i)], 0.0) << "t " << r.t << " spool " << i;
    }
  }
  const auto& stale = probe.rows[390];
  EXPECT_STREQ(stale.stop_reason, "input stale");
  const auto& fresh_not_armed = probe.rows[450];
  EXPECT_STREQ(fresh_not_armed.stop_reason, "re-arm: release and press the deadman");
  EXPECT_LT(speed(fresh_not_armed), 1e-3);
  EXPECT_STREQ(probe.rows[510].stop_reason, "deadman released");
  // Re-armed at 5.2 s; the command passes once the deadman has been held for 0.3 s (the stop
  // latch, 1 s, ran out long ago): running again, and the tip moves out, in the commanded
  // direction.
  EXPECT_STREQ(probe.rows[521].stop_reason, "arming: keep the deadman held");
  EXPECT_TRUE(std::isnan(probe.rows[549].cmd[0]));
  EXPECT_STREQ(probe.rows[551].status, "running");
  EXPECT_EQ(probe.rows[551].cmd[0], kOut.x());
  const auto& moving_again = probe.rows[650];
  EXPECT_STREQ(moving_again.status, "running");
  EXPECT_GT(speed(moving_again), 0.15);  // the start shaped to the grapple's swing (sway.md)
  const Eigen::Vector3d v(moving_again.tip_v[0], moving_again.tip_v[1], moving_again.tip_v[2]);
  EXPECT_GT(v.normalized().dot(kOut.normalized()), 0.999);
  EXPECT_GT(probe.rows[690].tip[0] - probe.rows[519].tip[0], 0.2);
}

TEST(LiveLoop, EveryFaultStopsWithItsReason) {
  const auto cfg = config::default_crane_config();
  struct Case {
    const char* reason;
    std::function<void(Script&)> fault;
  };
  const std::vector<Case> cases = {
      {"deadman released", [](Script& s) { s.deadman = false; }},
      {"device disconnected", [](Script& s) { s.state = input::SourceState::kDisconnected; }},
      {"command not finite", [](Script& s) { s.v.y() = NAN; }},
      {"command out of range", [](Script& s) { s.v.x() = 3.0; }},
  };
  for (const auto& c : cases) {
    ScriptedSource source([&](double t) {
      Script s = moving(t);
      if (t >= 1.5) c.fault(s);
      return s;
    });
    sim_backend::SimBackend machine(cfg.model, offline::sim_settings(cfg));
    Probe probe(400);
    control::run_live(cfg, source, machine, scripted_options(3.5, &probe), nullptr);
    ASSERT_EQ(probe.rows.size(), 350u) << c.reason;
    EXPECT_GT(speed(probe.rows[149]), 0.15) << c.reason;
    EXPECT_STREQ(probe.rows[150].stop_reason, c.reason);
    EXPECT_STREQ(probe.rows[151].status, "stopping") << c.reason;
    double peak_jerk = 0.0;
    for (std::size_t k = 150; k < probe.rows.size(); ++k) {
      peak_jerk = std::max(peak_jerk, std::abs(probe.rows[k].sdddot));
      EXPECT_TRUE(std::isnan(probe.rows[k].cmd[0])) << c.reason;
    }
    EXPECT_LE(peak_jerk, cfg.scaling.jerk_max_m_s3 + 1e-9) << c.reason;
    EXPECT_STREQ(probe.rows.back().status, "stopped") << c.reason;
    EXPECT_LT(speed(probe.rows.back()), 1e-3) << c.reason;
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(probe.rows.back().spool[static_cast<std::size_t>(i)], 0.0) << c.reason;
    }
  }
}

// A deadman that chatters from 1.5 s on (pressed and released in turn every cycle, every 30 ms,
// or every 0.25 s) while the tip moves out at 0.4 m/s: the operator's command never passes
// again, the tip comes to a jerk-limited stop and stays at rest with every valve neutral.
TEST(LiveLoop, AChatteringDeadmanStopsTheCraneAndKeepsItStopped) {
  const auto cfg = config::default_crane_config();
  for (const int period : {1, 3, 25}) {
    SCOPED_TRACE("chatter every " + std::to_string(period) + " cycles");
    ScriptedSource source([period](double t) {
      Script s = moving(t);
      const long k = std::lround(t * 100.0);
      if (k >= 150) s.deadman = ((k - 150) / period) % 2 == 1;
      return s;
    });
    sim_backend::SimBackend machine(cfg.model, offline::sim_settings(cfg));
    Probe probe(600);
    control::run_live(cfg, source, machine, scripted_options(5.0, &probe), nullptr);
    ASSERT_EQ(probe.rows.size(), 500u);
    EXPECT_GT(speed(probe.rows[149]), 0.15);
    int passed = 0;
    double peak_jerk = 0.0, late_peak_speed = 0.0;
    for (std::size_t k = 150; k < probe.rows.size(); ++k) {
      const auto& r = probe.rows[k];
      passed += std::isnan(r.cmd[0]) ? 0 : 1;
      peak_jerk = std::max(peak_jerk, std::abs(r.sdddot));
      if (k >= 300) late_peak_speed = std::max(late_peak_speed, speed(r));
    }
    EXPECT_EQ(passed, 0) << "cycles the chattering deadman let the command through";
    EXPECT_LE(peak_jerk, cfg.scaling.jerk_max_m_s3 + 1e-9);
    // At rest 1.5 s after the chatter began (the stop from 0.4 m/s takes about 0.9 s).
    EXPECT_LT(late_peak_speed, 1e-3);
    EXPECT_STREQ(probe.rows.back().status, "stopped");
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(probe.rows.back().spool[static_cast<std::size_t>(i)], 0.0);
    }
  }
}

TEST(LiveLoop, StopRequestBringsTheCraneToRestBeforeReturning) {
  const auto cfg = config::default_crane_config();
  std::atomic<bool> stop{false};
  ScriptedSource source([&](double t) {
    if (t >= 1.0) stop.store(true);
    return moving(t);
  });
  sim_backend::SimBackend machine(cfg.model, offline::sim_settings(cfg));
  Probe probe(1000);
  auto options = scripted_options(0.0, &probe);
  options.stop = &stop;
  const auto s = control::run_live(cfg, source, machine, options, nullptr);
  EXPECT_GT(s.cycles, 101);
  EXPECT_LT(s.cycles, 400);
  EXPECT_STREQ(probe.rows.back().stop_reason, "operator quit");
  EXPECT_STREQ(probe.rows.back().status, "stopped");
  for (int i = 0; i < 4; ++i) EXPECT_EQ(probe.rows.back().spool[static_cast<std::size_t>(i)], 0.0);
}

TEST(LiveLoop, CyclesAllocateNothing) {
  const auto cfg = config::default_crane_config();
  ScriptedSource source([](double t) {
    Script s = moving(t);
    if (t > 1.0 && t < 1.3) s.fresh = false;
    if (t > 1.5 && t < 1.6) s.deadman = false;
    return s;
  });
  sim_backend::SimBackend machine(cfg.model, offline::sim_settings(cfg));
  Probe probe(300);
  std::vector<input::ReplayRow> record;
  auto options = scripted_options(3.0, &probe);
  options.record = &record;
  options.record_capacity = 400;
  control::run_live(cfg, source, machine, options, nullptr);
  ASSERT_EQ(probe.allocations.size(), 300u);
  // std::function calls in the scripted source allocate nothing either (captureless lambda).
  EXPECT_EQ(probe.allocations.back() - probe.allocations[1], 0);
  // Every row carries the live fields.
  const auto& r = probe.rows[50];
  EXPECT_GT(std::abs(r.qdot[1]) + std::abs(r.qdot[2]) + std::abs(r.qdot[3]), 0.0);
  EXPECT_GT(r.cylinder_pos[1], 0.0);
  EXPECT_NE(r.cylinder_vel[1], 0.0);
}

// The drive mode (sim --drive): one stick drives the base, flow-bounded, while the tip moves; a
// released deadman stops both. With one pump for the drive and the crane, the motors and the
// crane together never draw more than Q_max.
TEST(LiveLoop, DriveModeMovesTheBaseWithinTheFlowBoundAndStopsWithTheDeadman) {
  const auto cfg = config::default_crane_config();
  config::BaseConfig base = config::default_base_config();
  for (const bool shared : {false, true}) {
    SCOPED_TRACE(shared ? "shared pump" : "separate pumps");
    sim_backend::MobileCraneBackend machine(cfg.model, offline::sim_settings(cfg), base.model,
                                            dynamics::BasePose{}, shared);
    // Full stick ahead and a quarter of the steering to the left while the tip moves out, for
    // 8 s; then the deadman released.
    ScriptedSource source([](double t) {
      Script s;
      s.v = kOut;
      s.deadman = t >= 0.1 && t < 8.0;
      s.drive = Eigen::Vector2d(1.0, 0.25);
      return s;
    });
    Probe probe(1200);
    control::LiveOptions o = scripted_options(11.0, &probe);
    o.base = &base.model;
    control::run_live(cfg, source, machine, o, nullptr);
    ASSERT_FALSE(probe.rows.empty());
    const double q_max = base.model.pump_max_flow_m3_s;
    const double kappa = 0.25 * dynamics::max_curvature_1_m(base.model);
    const double v_max = q_max / dynamics::flow_per_speed_m2(base.model, kappa);
    double peak_v = 0.0;
    for (const auto& r : probe.rows) {
      ASSERT_TRUE(r.base_present);
      EXPECT_EQ(r.base_shared_pump, shared);
      ASSERT_LE(r.base_flow_sum_m3s, q_max * (1 + 1e-9)) << "t = " << r.t;
      if (shared) {
        ASSERT_LE(r.base_flow_sum_m3s + r.pump_flow_m3s, q_max * (1 + 1e-9)) << r.t;
      }
      ASSERT_LE(r.base_command[0], v_max * (1 + 1e-9));
      if (r.base_command[0] > 0.0) {
        EXPECT_NEAR(r.base_command[1] / r.base_command[0], kappa, 1e-9);  // the curvature
      }
      peak_v = std::max(peak_v, r.base_velocity[0]);
    }
    // The base reached the flow bound's speed (the lag's time constant is 0.3 s) and turned
    // left; the deadman's release stopped the command at once and the base within its lag.
    EXPECT_NEAR(peak_v, v_max, 0.01 * v_max);
    const control::LogRow& at_release = probe.rows[static_cast<std::size_t>(8.0 / 0.01) + 1];
    EXPECT_EQ(at_release.base_command[0], 0.0);
    const control::LogRow& last = probe.rows.back();
    EXPECT_LT(std::abs(last.base_velocity[0]), 0.01 * v_max);
    EXPECT_GT(last.base_pose[0], 1.0);
    EXPECT_GT(last.base_pose[1], 0.0);
    EXPECT_GT(last.base_pose[2], 0.0);
  }
}

TEST(LiveLoop, FixedBaseIgnoresTheDriveStick) {
  const auto cfg = config::default_crane_config();
  sim_backend::SimBackend machine(cfg.model, offline::sim_settings(cfg));
  ScriptedSource source([](double t) {
    Script s = moving(t);
    s.drive = Eigen::Vector2d(1.0, 0.0);
    return s;
  });
  Probe probe(200);
  control::run_live(cfg, source, machine, scripted_options(1.0, &probe), nullptr);
  for (const auto& r : probe.rows) {
    EXPECT_FALSE(r.base_present);
    EXPECT_EQ(r.base_command[0], 0.0);
  }
}
