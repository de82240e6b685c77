// End to end: replay -> controller -> simulated crane -> log, on the reference crane. The
// physical point of the product: when the pump saturates, the tip keeps its commanded direction
// with flow prescaling and leaves it without.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/csv_log.hpp"
#include "craneassist/control/replay_runner.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

using namespace craneassist;

namespace {

const std::string kSource = CRANEASSIST_SOURCE_DIR;

// The reference crane with a 100 L/min pump and ample engine power: flow is the binding limit,
// so this is the situation flow prescaling exists for.
config::CraneConfig flow_limited_crane() {
  auto cfg = config::default_crane_config();
  cfg.model.pump.max_flow_m3_s = 100e-3 / 60.0;
  cfg.model.pump.prime_mover_power_w = 200e3;
  return cfg;
}

struct ReplayRun {
  control::RunSummary summary;
  double min_elevation_deg = 90.0;  // of the measured tip velocity while moving fast
};

ReplayRun run(const config::CraneConfig& cfg, const std::string& replay_file,
              control::ScalingMode mode, const std::filesystem::path& log_path) {
  const auto replay = input::Replay::load_file(kSource + "/examples/replays/" + replay_file);
  sim_backend::SimBackend machine(cfg.model, {cfg.simulation.step_s, cfg.simulation.q_initial});
  control::CsvLog log(log_path, cfg.model.dof());
  control::RunOptions options;
  options.controller.mode = mode;
  ReplayRun r;
  r.summary = control::run_replay(cfg, replay, machine, options, &log);
  // The elevation of the measured tip velocity, from the log (independent of the summary).
  std::ifstream in(log_path);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string cell;
    std::vector<double> v;
    for (int c = 0; c < 13 && std::getline(ss, cell, ','); ++c) v.push_back(std::stod(cell));
    const double t = v[0], vx = v[10], vy = v[11], vz = v[12];
    const double speed = std::sqrt(vx * vx + vy * vy + vz * vz);
    if (t > 1.0 && t < 3.5 && speed > 0.5) {
      r.min_elevation_deg = std::min(r.min_elevation_deg, std::asin(vy / speed) * 180.0 / M_PI);
    }
  }
  return r;
}

}  // namespace

TEST(ReplayEndToEnd, FlowPrescalingKeepsTheTipDirectionWhenThePumpSaturates) {
  const auto cfg = flow_limited_crane();
  const auto dir = std::filesystem::temp_directory_path();
  const ReplayRun unscaled = run(cfg, "combined_move.csv", control::ScalingMode::kNone,
                                 dir / "craneassist_e2e_unscaled.csv");
  const ReplayRun scaled = run(cfg, "combined_move.csv", control::ScalingMode::kFlowOnly,
                               dir / "craneassist_e2e_scaled.csv");
  const double commanded_elevation = std::asin(0.8 / std::sqrt(0.36 + 0.64 + 1.44)) * 180 / M_PI;

  // Closing-note figures.
  std::printf(
      "[ figures  ] no scaling: max %.2f deg, rms %.2f deg, saturated %ld cycles, "
      "min tip elevation %.1f deg (commanded %.1f)\n",
      unscaled.summary.max_direction_error_deg, unscaled.summary.rms_direction_error_deg,
      unscaled.summary.pump_saturated_cycles, unscaled.min_elevation_deg, commanded_elevation);
  std::printf(
      "[ figures  ] flow prescaling: max %.2f deg, rms %.2f deg, saturated %ld cycles, "
      "min tip elevation %.1f deg\n",
      scaled.summary.max_direction_error_deg, scaled.summary.rms_direction_error_deg,
      scaled.summary.pump_saturated_cycles, scaled.min_elevation_deg);

  // Without scaling the pump saturates, the most loaded cylinder starves and the tip dips.
  EXPECT_GT(unscaled.summary.pump_saturated_cycles, 100);
  EXPECT_GT(unscaled.summary.max_direction_error_deg, 20.0);
  EXPECT_LT(unscaled.min_elevation_deg, commanded_elevation - 20.0);
  // With flow prescaling the reference keeps the commanded direction exactly and the machine
  // follows it closely.
  EXPECT_LT(scaled.summary.max_reference_direction_error_deg, 0.01);
  EXPECT_LT(scaled.summary.pump_saturated_cycles, 20);
  EXPECT_LT(scaled.summary.max_direction_error_deg, 8.0);
  EXPECT_LT(scaled.summary.rms_direction_error_deg, 2.0);
  EXPECT_GT(scaled.min_elevation_deg, commanded_elevation - 8.0);
  EXPECT_GT(scaled.summary.limit_cycles[static_cast<std::size_t>(scaling::ActiveLimit::kFlow)], 50);
}

TEST(ReplayEndToEnd, DemoRunsAndLogsEveryDocumentedColumn) {
  const auto cfg = config::default_crane_config();
  const auto log_path = std::filesystem::temp_directory_path() / "craneassist_e2e_demo.csv";
  const ReplayRun r = run(cfg, "demo.csv", control::ScalingMode::kFull, log_path);
  const auto replay = input::Replay::load_file(kSource + "/examples/replays/demo.csv");
  // The replay, 1 s to settle, and the end of the run's stop: it is measured at rest for the
  // valves' lag (delay plus time constant, 20 cycles) before the valves go neutral; the swinging
  // grapple still moves the tip a little after the reference has come to rest (under a second).
  const int lag_cycles = static_cast<int>(
      std::round((cfg.model.valves.delay_s + cfg.model.valves.time_constant_s) * 100));
  EXPECT_EQ(r.summary.cycles, static_cast<int>(std::round((replay.end_time_s() + 1.0) * 100)) + 1 +
                                  r.summary.stopped_cycles);
  EXPECT_EQ(r.summary.log_rows_dropped, 0u);
  EXPECT_GE(r.summary.stopped_cycles, lag_cycles);
  EXPECT_LE(r.summary.stopped_cycles, lag_cycles + 100);
  EXPECT_EQ(r.summary.stop.end, control::StopEnd::kAtRest);
  EXPECT_GT(r.summary.tip_path_m, 5.0);
  EXPECT_GT(r.summary.energy_j, 1e3);
  EXPECT_LE(r.summary.peak_power_w, cfg.model.pump.prime_mover_power_w * 1.001);
  EXPECT_LT(r.summary.rms_direction_error_deg, 3.0);

  std::ifstream in(log_path);
  std::string header = ",";
  std::string first_line;
  std::getline(in, first_line);
  header += first_line;
  header += ",";
  for (const char* column : {"t",
                             "cmd_vx",
                             "cmd_vy",
                             "cmd_vz",
                             "ref_vx",
                             "ref_vy",
                             "ref_vz",
                             "tip_x",
                             "tip_y",
                             "tip_z",
                             "tip_vx",
                             "tip_vy",
                             "tip_vz",
                             "q1",
                             "q2",
                             "q3",
                             "q4",
                             "q1_ref",
                             "q2_ref",
                             "q3_ref",
                             "q4_ref",
                             "pump_flow_m3s",
                             "pump_pressure_pa",
                             "pump_power_w",
                             "energy_j",
                             "active_limit"}) {
    std::string needle = ",";
    needle += column;
    needle += ",";
    EXPECT_NE(header.find(needle), std::string::npos) << column;
  }
  int rows = 0;
  std::string line;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, r.summary.cycles);
}

TEST(ReplayEndToEnd, ReachingTheJointRangeEndStopsWithoutHittingIt) {
  // Drive the extension out for far longer than its stroke: the SNS bounds bring it to rest
  // at the end within the acceleration limit and the tip carries on with the other joints.
  auto cfg = config::default_crane_config();
  const auto replay = input::Replay::parse("t,v_x,v_y,v_z\n0,0.5,0,0\n12,0,0,0\n", "out.csv");
  sim_backend::SimBackend machine(cfg.model, {cfg.simulation.step_s, cfg.simulation.q_initial});
  control::RunOptions options;
  const auto s = control::run_replay(cfg, replay, machine, options, nullptr);
  EXPECT_GT(s.limit_cycles[static_cast<std::size_t>(scaling::ActiveLimit::kJointLimit)], 0);
  valves::MachineState state;
  machine.read(state);
  for (int i = 0; i < 4; ++i) {
    EXPECT_GE(state.q[i], cfg.model.joints[static_cast<std::size_t>(i)].q_min - 0.01);
    EXPECT_LE(state.q[i], cfg.model.joints[static_cast<std::size_t>(i)].q_max + 0.01);
  }
}

// The crane config's ranges (docs/config.md#ranges) are where the simulator and the dynamics
// model run: models at their edges load and run the controller on the simulated crane without an
// abort or an exception. The worst mix: every body either at the lightest and slimmest (1 kg,
// radius of gyration 1 cm) or at the heaviest and largest (100 t, 30 m, its centre of mass 100 m
// out), with and without 100 m links, a 100 t payload and 20 m/s^2 of gravity tilted 45 deg.
// Outside them, a 1 mm radius of gyration next to such masses, the dynamics probe already fails.
TEST(ReplayEndToEnd, ModelsAtTheConfigRangeEdgesRun) {
  std::ifstream in(kSource + "/config/cranes/k70m.yaml");
  const std::string k70m{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const auto edit = [](std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? text : text.replace(at, from.size(), to);
  };
  struct BodyLines {
    const char *mass, *com, *inertia;
  };
  const BodyLines bodies[] = {
      {"    mass: 500 kg", "    com: 0.208 -0.805 0 m", "    inertia: 118 22.5 118 kg*m^2"},
      {"    mass: 420 kg", "    com: -1.754 0 0 m", "    inertia: 10 429 429 kg*m^2"},
      {"    mass: 300 kg", "    com: 0 0 1.1 m", "    inertia: 156 156 8 kg*m^2"},
      {"    mass: 160 kg", "    com: 0 1.85 0 m", "    inertia: 182 4 182 kg*m^2"},
      {"    mass: 180 kg", "    com: 0 0 0 m", "    inertia: 6.5 6.5 6.5 kg*m^2"},
  };
  const auto replay =
      input::Replay::parse("t,v_x,v_y,v_z\n0,0.2,0.1,0.1\n0.5,0,0,0\n", "edges.csv");
  int runs = 0;
  for (int heavy = 0; heavy < 32; ++heavy) {
    for (const bool long_links : {false, true}) {
      std::string text = k70m;
      text = edit(text, "gravity: 0 0 -9.81 m/s^2", "gravity: 0 14.142 -14.142 m/s^2");
      text = edit(text, "  mass: 0 kg, assumed", "  mass: 1e5 kg, assumed");  // the payload
      for (int b = 0; b < 5; ++b) {
        const bool h = (heavy >> b & 1) != 0;
        text = edit(text, bodies[b].mass, h ? "    mass: 1e5 kg" : "    mass: 1 kg");
        text = edit(text, bodies[b].inertia,
                    h ? "    inertia: 9e7 9e7 9e7 kg*m^2" : "    inertia: 1e-4 1e-4 1e-4 kg*m^2");
        if (h) text = edit(text, bodies[b].com, "    com: 100 -100 100 m");
      }
      if (long_links) {
        text = edit(text, "    a: -0.208 m", "    a: -100 m");
        text = edit(text, "    d: 1.605 m", "    d: -100 m");
        text = edit(text, "    a: 3.504 m", "    a: 100 m");
        text = edit(text, "    a: 0.376 m", "    a: -100 m");
        text = edit(text, "    d: 2.13 m", "    d: 100 m");
      }
      SCOPED_TRACE("heavy bodies " + std::to_string(heavy) + (long_links ? ", 100 m links" : ""));
      const auto cfg = config::parse_crane_config(text, "edges.yaml");
      sim_backend::SimBackend machine(cfg.model, {cfg.simulation.step_s, cfg.simulation.q_initial});
      control::RunOptions options;
      options.settle_s = 0.5;
      const auto s = control::run_replay(cfg, replay, machine, options, nullptr);
      EXPECT_GE(s.cycles, 100);  // the replay and the settling second, to the end
      valves::MachineState state;
      machine.read(state);
      EXPECT_TRUE(state.q.allFinite());
      ++runs;
    }
  }
  // The light end everywhere: every body 1 kg and slim, no gravity.
  std::string text = edit(k70m, "gravity: 0 0 -9.81 m/s^2", "gravity: 0 0 0 m/s^2");
  for (const auto& b : bodies) {
    text = edit(text, b.mass, "    mass: 1 kg");
    text = edit(text, b.inertia, "    inertia: 1e-4 1e-4 2e-4 kg*m^2");
  }
  const auto cfg = config::parse_crane_config(text, "light.yaml");
  sim_backend::SimBackend machine(cfg.model, {cfg.simulation.step_s, cfg.simulation.q_initial});
  const auto s = control::run_replay(cfg, replay, machine, {}, nullptr);
  EXPECT_GT(s.tip_path_m, 0.0);
  EXPECT_EQ(runs, 64);
}
