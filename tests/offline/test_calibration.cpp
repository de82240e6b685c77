// Valve calibration on the simulator (craneassist calibrate): the sweep reproduces the simulated
// valves' dead zone and top speeds, the fit is monotone, the YAML block loads, and a crane
// driven through the calibrated tables tracks as it does with the straight-line model.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/replay_runner.hpp"
#include "craneassist/dynamics/valve_table.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/offline/calibration.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"
#include "craneassist/valves/proportional_valves.hpp"

using namespace craneassist;

namespace {

const std::string kSource = CRANEASSIST_SOURCE_DIR;

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Calibrated once for the whole file (about a second of simulation).
const std::vector<offline::SectionCalibration>& k70m_calibration() {
  static const std::vector<offline::SectionCalibration> results = [] {
    const auto cfg = config::default_crane_config();
    std::vector<offline::SectionCalibration> r;
    for (int i = 0; i < cfg.model.dof(); ++i) {
      r.push_back(offline::calibrate_section(cfg, i, offline::CalibrationOptions{}));
    }
    return r;
  }();
  return results;
}

// Tolerances: the simulator's valves are the straight line through dead_zone 0.53 and each
// cylinder's max_speed; the sweep recovers the dead-band edges within 0.005 of the command range
// and the top speeds within 1 %.
constexpr double kDeadBandTolerance = 0.005;
constexpr double kSpeedTolerance = 0.01;

TEST(Calibration, ReproducesTheSimulatedDeadZoneAndTopSpeeds) {
  const auto cfg = config::default_crane_config();
  const double dz = cfg.model.valves.dead_zone;
  ASSERT_EQ(dz, 0.53);
  for (const auto& r : k70m_calibration()) {
    const auto& cyl = cfg.model.cylinders[static_cast<std::size_t>(r.section)];
    SCOPED_TRACE(cyl.name);
    ASSERT_EQ(dynamics::check_valve_table(r.table), "");
    for (const auto& p : r.points) EXPECT_TRUE(p.valid) << p.command;
    EXPECT_NEAR(r.dead_band_extend, dz, kDeadBandTolerance);
    EXPECT_NEAR(r.dead_band_retract, -dz, kDeadBandTolerance);
    EXPECT_NEAR(r.max_extend_m_s, cyl.v_max_m_s, kSpeedTolerance * cyl.v_max_m_s);
    EXPECT_NEAR(r.max_retract_m_s, cyl.v_max_m_s, kSpeedTolerance * cyl.v_max_m_s);
    // Everywhere, the table is the simulator's characteristic.
    for (double u = -1.0; u <= 1.0; u += 0.01) {
      EXPECT_NEAR(dynamics::valve_table_velocity(r.table, u),
                  valves::ProportionalValves::velocity_from_spool(u, dz, cyl.v_max_m_s),
                  kSpeedTolerance * cyl.v_max_m_s)
          << u;
    }
  }
}

TEST(Calibration, FitIsMonotoneAndFindsTheDeadBandEdge) {
  // A noisy sweep: the 0.9 level reads below 0.8 (a violation), the dead band ends at 0.52.
  std::vector<offline::SweepPoint> points;
  auto line = [](double u) { return std::copysign(std::max(std::abs(u) - 0.52, 0.0) * 0.5, u); };
  for (double u : {-1.0, -0.8, -0.7, -0.6, -0.5, -0.3, 0.0, 0.3, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0}) {
    points.push_back({u, line(u), true});
  }
  points[12].velocity_m_s = 0.13;  // 0.9: true 0.19, reads below 0.8's 0.14
  points[4].velocity_m_s = 1e-6;   // drift in the dead band
  points[13].valid = false;        // 1.0 hit the end stop: not used
  const auto t = offline::fit_valve_table(points, 1e-4);
  ASSERT_EQ(dynamics::check_valve_table(t), "") << t.command.size();
  EXPECT_NEAR(dynamics::valve_table_dead_band_edge(t, 1.0), 0.52, 1e-12);
  EXPECT_NEAR(dynamics::valve_table_dead_band_edge(t, -1.0), -0.52, 1e-12);
  // 0.8 and 0.9 pooled into one point at their mean command and velocity.
  EXPECT_NEAR(t.command.back(), 0.85, 1e-12);
  EXPECT_NEAR(t.velocity_m_s.back(), 0.135, 1e-12);
  EXPECT_NEAR(dynamics::valve_table_command(t, 0.09), 0.7, 1e-12);
  EXPECT_DOUBLE_EQ(t.command.front(), -1.0);
}

TEST(Calibration, YamlBlockLoadsIntoTheConfig) {
  const auto cfg = config::default_crane_config();
  const std::string block =
      offline::valve_tables_yaml(cfg.model, k70m_calibration(), "craneassist calibrate: test");
  std::string text = read_file(kSource + "/config/cranes/k70m.yaml");
  const std::string anchor = "    delay: 0.15 s, paper";
  const auto eol = text.find('\n', text.find(anchor));
  text.insert(eol + 1, block);
  const auto loaded = config::parse_crane_config(text, "calibrated.yaml");
  ASSERT_EQ(loaded.model.valves.tables.size(), 4u);
  for (const auto& r : k70m_calibration()) {
    const auto& t = loaded.model.valves.tables[static_cast<std::size_t>(r.section)];
    ASSERT_EQ(t.command.size(), r.table.command.size());
    for (std::size_t k = 0; k < t.command.size(); ++k) {
      EXPECT_NEAR(t.command[k], r.table.command[k], 1e-5);
      EXPECT_NEAR(t.velocity_m_s[k], r.table.velocity_m_s[k], 1e-6);
    }
  }
}

// The demo replay through the calibrated tables and through the straight line: the same
// tracking (direction error within 0.2 deg, path and peak speed within 1 %).
TEST(Calibration, CalibratedTablesTrackLikeTheStraightLine) {
  const auto replay = input::Replay::load_file(kSource + "/examples/replays/demo.csv");
  auto run = [&](const config::CraneConfig& cfg) {
    sim_backend::SimBackend machine(cfg.model, {cfg.simulation.step_s, cfg.simulation.q_initial});
    return control::run_replay(cfg, replay, machine, control::RunOptions{}, nullptr);
  };
  const auto plain_cfg = config::default_crane_config();
  auto table_cfg = plain_cfg;
  for (const auto& r : k70m_calibration()) table_cfg.model.valves.tables.push_back(r.table);
  const auto plain = run(plain_cfg);
  const auto tabled = run(table_cfg);
  EXPECT_NEAR(tabled.rms_direction_error_deg, plain.rms_direction_error_deg, 0.2);
  EXPECT_NEAR(tabled.max_direction_error_deg, plain.max_direction_error_deg, 0.5);
  EXPECT_NEAR(tabled.tip_path_m, plain.tip_path_m, 0.01 * plain.tip_path_m);
  EXPECT_NEAR(tabled.peak_tip_speed_m_s, plain.peak_tip_speed_m_s, 0.01 * plain.peak_tip_speed_m_s);
  RecordProperty("rms_direction_error_plain_deg", std::to_string(plain.rms_direction_error_deg));
  RecordProperty("rms_direction_error_table_deg", std::to_string(tabled.rms_direction_error_deg));
}

}  // namespace

// The sweep identifies a machine's spool delay and time constant from the levels' onsets and
// its dead band from the table, on machines that differ from the model: the lag within 10 %,
// the dead band within 5 % (docs/valves.md#identification), on every section.
TEST(Calibration, IdentifiesTheMachinesSpoolDelayLagAndDeadBand) {
  struct Machine {
    const char* name;
    double time_constant_s, delay_s, dead_zone, gain;
  };
  for (const Machine& m : {Machine{"the model's", 0.05, 0.15, 0.53, 1.0},
                           Machine{"fast, late, narrow, strong", 0.025, 0.17, 0.265, 1.2},
                           Machine{"slow, wide, weak", 0.1, 0.15, 0.795, 0.8}}) {
    SCOPED_TRACE(m.name);
    auto cfg = config::default_crane_config();
    for (auto& v : cfg.simulation.valves) {
      v.time_constant_s = m.time_constant_s;
      v.delay_s = m.delay_s;
      v.dead_zone = m.dead_zone;
      v.gain = m.gain;
    }
    for (int i = 0; i < cfg.model.dof(); ++i) {
      SCOPED_TRACE("section " + std::to_string(i));
      const auto r = offline::calibrate_section(cfg, i, offline::CalibrationOptions{});
      ASSERT_TRUE(r.dynamics.identified) << r.dynamics.why_not;
      EXPECT_NEAR(r.dynamics.time_constant_s, m.time_constant_s, 0.1 * m.time_constant_s);
      EXPECT_NEAR(r.dynamics.delay_s, m.delay_s, 0.1 * m.delay_s);
      EXPECT_NEAR(r.dead_band_extend, m.dead_zone, 0.05 * m.dead_zone);
      EXPECT_NEAR(-r.dead_band_retract, m.dead_zone, 0.05 * m.dead_zone);
      EXPECT_NEAR(r.max_extend_m_s,
                  m.gain * cfg.model.cylinders[static_cast<std::size_t>(i)].v_max_m_s,
                  0.01 * r.max_extend_m_s);
      EXPECT_GE(r.dynamics.levels, 6);  // a wide band leaves 3 levels each way
      EXPECT_LT(r.dynamics.residual_s, 0.005);
    }
  }
}

// Not identified, with the reason: too few levels that move.
TEST(Calibration, RefusesSpoolDynamicsFromTooFewMovingLevels) {
  auto options = offline::CalibrationOptions{};
  options.levels = {0.3, 0.6};  // one level beyond the 0.53 band each way
  const auto r = offline::calibrate_section(config::default_crane_config(), 1, options);
  EXPECT_FALSE(r.dynamics.identified);
  EXPECT_NE(r.dynamics.why_not.find("3 needed"), std::string::npos) << r.dynamics.why_not;
}

namespace {

// The sweep a machine gets (moves to mid-stroke in between, ramped spools, levels cut short
// before the end margin), run on the simulator as the machine: one crane for the whole sweep,
// from the config's initial pose. It must give the placed sweep's tables.
TEST(Calibration, MachineSweepOnTheSimulatorGivesThePlacedTables) {
  const auto cfg = config::default_crane_config();
  sim_backend::SimBackend machine(cfg.model, {cfg.simulation.step_s, cfg.simulation.q_initial});
  for (const auto& placed : k70m_calibration()) {
    const auto& cyl = cfg.model.cylinders[static_cast<std::size_t>(placed.section)];
    SCOPED_TRACE(cyl.name);
    std::vector<offline::SweepLogRow> log;
    const auto sweep = offline::calibrate_section_on_machine(
        cfg, machine, placed.section, offline::CalibrationOptions{}, nullptr, &log);
    ASSERT_EQ(sweep.end, offline::SweepEnd::kComplete) << sweep.reason;
    const auto& r = sweep.section;
    ASSERT_EQ(dynamics::check_valve_table(r.table), "");
    for (const auto& p : r.points) EXPECT_TRUE(p.valid) << p.command;
    EXPECT_NEAR(r.dead_band_extend, placed.dead_band_extend, kDeadBandTolerance);
    EXPECT_NEAR(r.dead_band_retract, placed.dead_band_retract, kDeadBandTolerance);
    EXPECT_NEAR(r.max_extend_m_s, placed.max_extend_m_s, kSpeedTolerance * cyl.v_max_m_s);
    EXPECT_NEAR(r.max_retract_m_s, placed.max_retract_m_s, kSpeedTolerance * cyl.v_max_m_s);
    double worst = 0.0;
    for (std::size_t k = 0; k < r.points.size(); ++k) {
      ASSERT_EQ(r.points[k].command, placed.points[k].command);
      worst = std::max(worst, std::abs(r.points[k].velocity_m_s - placed.points[k].velocity_m_s));
    }
    EXPECT_LT(worst, 0.001 * cyl.v_max_m_s);
    std::printf("%s: sweep %.1f s of machine time, worst level %.3g %% of max_speed\n",
                cyl.name.c_str(), sweep.duration_s, 100.0 * worst / cyl.v_max_m_s);
  }
}

}  // namespace
