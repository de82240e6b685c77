// Scenario-suite manifests (app/scenario_suite.hpp, docs/suite-format.md): the shipped suite,
// targets merged per run, and every mistake named by file, line and field.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/offline/scenario_suite.hpp"
#include "thrown_error.hpp"

using namespace craneassist;

namespace {

const std::filesystem::path kReplays =
    std::filesystem::path(CRANEASSIST_SOURCE_DIR) / "examples/replays";

config::ConfigError error_of(const std::string& yaml) {
  return test::thrown_error<config::ConfigError>(
      [&] {
        const auto suite = offline::parse_suite(yaml, "test.yaml", kReplays);
        offline::check_suite(suite, config::default_crane_config());
      },
      "no error for:\n" + yaml);
}

}  // namespace

TEST(ScenarioSuite, TheShippedSuiteExpandsEveryPose) {
  const auto suite = offline::load_suite(kReplays / "suite.yaml");
  offline::check_suite(suite, config::default_crane_config());
  ASSERT_EQ(suite.runs.size(), 27u);
  EXPECT_EQ(suite.runs[0].name(), "suite/push_x_plus.csv @default");
  EXPECT_EQ(suite.runs[1].name(), "suite/push_x_plus.csv @folded");
  EXPECT_EQ(suite.runs[1].pose_text, "lift=0 deg, tilt=-125 deg, extension=0.2 m");
  ASSERT_TRUE(suite.runs[0].targets.lateral_speed_m_s);
  EXPECT_DOUBLE_EQ(*suite.runs[0].targets.lateral_speed_m_s, 0.03);
  const auto& heavy = suite.runs[suite.runs.size() - 3];
  EXPECT_EQ(heavy.name(), "heavy_lift.csv @default");
  EXPECT_EQ(heavy.payload_kg, 650.0);
  EXPECT_FALSE(heavy.payload_known);  // unannounced: the crane scale weighs it
  // The loading cycles with a log nobody announces (docs/loads.md).
  EXPECT_EQ(suite.runs[suite.runs.size() - 2].name(), "work_cycle.csv @default");
  EXPECT_EQ(suite.runs.back().name(), "work_cycle_slip.csv @default");
  ASSERT_TRUE(heavy.targets.peak_power_share && heavy.targets.direction_error_rad &&
              heavy.targets.stall_events);
  EXPECT_DOUBLE_EQ(*heavy.targets.peak_power_share, 1.02);
  EXPECT_NEAR(*heavy.targets.direction_error_rad, 2.0 * M_PI / 180.0, 1e-15);
  EXPECT_EQ(*heavy.targets.stall_events, 0);  // the default, merged
}

TEST(ScenarioSuite, MistakesNameFileLineAndField) {
  const std::string head = "format: craneassist-suite/1\n";
  auto e = error_of("format: craneassist-suite/9\nruns:\n  - replay: demo.csv\n");
  EXPECT_EQ(e.field(), "format");
  EXPECT_EQ(e.line(), 1);
  e = error_of(head + "runs:\n  - replay: nowhere.csv\n");
  EXPECT_EQ(e.field(), "runs[0].replay");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(e.reason().find("no such file"), std::string::npos);
  // A name the file system refuses (longer than NAME_MAX) is the entry's error, not a crash.
  e = error_of(head + "runs:\n  - replay: " + std::string(300, 'a') + ".csv\n");
  EXPECT_EQ(e.field(), "runs[0].replay");
  EXPECT_NE(e.reason().find("cannot use"), std::string::npos) << e.reason();
  e = error_of(head + "runs:\n  - replay: demo.csv\n    payload_known: maybe\n");
  EXPECT_EQ(e.field(), "runs[0].payload_known");
  EXPECT_EQ(e.line(), 4);
  EXPECT_NE(e.reason().find("expected true or false, got 'maybe'"), std::string::npos);
  e = error_of(head + "runs:\n  - replay: demo.csv\n    poses: [folded]\n");
  EXPECT_EQ(e.field(), "runs[0].poses");
  EXPECT_NE(e.reason().find("no pose named 'folded'"), std::string::npos);
  e = error_of(head +
               "poses:\n  low: lift=5 deg, boom=1 m\nruns:\n  - replay: demo.csv\n"
               "    poses: [low]\n");
  EXPECT_EQ(e.field(), "poses.low");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(e.reason().find("'boom': no joint of that name"), std::string::npos);
  e = error_of(head + "targets:\n  lateral_speed: 3 cm\nruns:\n  - replay: demo.csv\n");
  EXPECT_EQ(e.field(), "targets.lateral_speed");
  e = error_of(head + "targets:\n  stall_events: -1\nruns:\n  - replay: demo.csv\n");
  EXPECT_EQ(e.field(), "targets.stall_events");
  e = error_of(head + "runs:\n  - replay: demo.csv\n    payload: 650 km\n");
  EXPECT_EQ(e.field(), "runs[0].payload");
  e = error_of(head + "runs:\n  - replay: demo.csv\n    speed: 2\n");
  EXPECT_EQ(e.field(), "runs[0].speed");
  e = error_of(head + "runs: []\n");
  EXPECT_EQ(e.field(), "runs");
  e = error_of(head + "runs:\n  - replay: [demo.csv\n");
  EXPECT_GT(e.line(), 0);
}

TEST(ScenarioSuite, ARunMissingATargetSaysWhichAndByHowMuch) {
  auto suite = offline::parse_suite(
      "format: craneassist-suite/1\nruns:\n  - replay: heavy_lift.csv\n    payload: 650 kg\n"
      "    targets: {peak_power: 0.1, direction_error: 0.001 deg}\n",
      "tight.yaml", kReplays);
  const auto out = offline::run_suite_run(config::default_crane_config(), suite.runs[0], "", {});
  ASSERT_EQ(out.missed.size(), 2u);
  EXPECT_NE(out.missed[0].find("peak power"), std::string::npos) << out.missed[0];
  EXPECT_NE(out.missed[0].find("> 0.100"), std::string::npos) << out.missed[0];
  EXPECT_NE(out.missed[1].find("direction error"), std::string::npos) << out.missed[1];
  EXPECT_FALSE(out.ok());
}

// The loading-cycle benchmark (examples/replays/loading.yaml): each cycle as craneassist runs it
// and on the flow-only baseline, the waits' targets, and the new fields' mistakes.
TEST(ScenarioSuite, TheLoadingBenchmarkPairsEachCycleWithItsBaseline) {
  const auto suite = offline::load_suite(kReplays / "loading.yaml");
  offline::check_suite(suite, config::default_crane_config());
  ASSERT_EQ(suite.runs.size(), 6u);
  for (std::size_t i = 0; i < suite.runs.size(); i += 2) {
    const auto& ours = suite.runs[i];
    const auto& base = suite.runs[i + 1];
    EXPECT_EQ(ours.scaling, control::ScalingMode::kFull);
    EXPECT_FALSE(ours.sway_damping.has_value());
    EXPECT_EQ(base.scaling, control::ScalingMode::kFlowOnly);
    ASSERT_TRUE(base.sway_damping.has_value());
    EXPECT_FALSE(*base.sway_damping);
    EXPECT_TRUE(ours.same_motion(base));
    EXPECT_EQ(base.name(), ours.name() + " (scaling flow, no sway damping)");
    ASSERT_TRUE(ours.targets.timed_out_waits);
    EXPECT_EQ(*ours.targets.timed_out_waits, 0);
  }
  EXPECT_FALSE(suite.runs[0].same_motion(suite.runs[2]));
}

TEST(ScenarioSuite, TheBaselineFieldsAndWaitTargetsAreCheckedAndNamed) {
  const std::string head = "format: craneassist-suite/1\nruns:\n  - replay: demo.csv\n";
  auto e = error_of(head + "    scaling: fast\n");
  EXPECT_EQ(e.field(), "runs[0].scaling");
  EXPECT_EQ(e.line(), 4);
  EXPECT_NE(e.reason().find("expected full, flow or none, got 'fast'"), std::string::npos);
  e = error_of(head + "    sway_damping: off\n");
  EXPECT_EQ(e.field(), "runs[0].sway_damping");
  EXPECT_NE(e.reason().find("expected true or false, got 'off'"), std::string::npos);
  e = error_of(head + "    wait_swing: 2 m\n");
  EXPECT_EQ(e.field(), "runs[0].wait_swing");
  e = error_of(head + "    wait_swing: 0 deg\n");
  EXPECT_EQ(e.field(), "runs[0].wait_swing");
  e = error_of(head + "    targets: {residual_swing: 2 kg}\n");
  EXPECT_EQ(e.field(), "runs[0].targets.residual_swing");
  e = error_of(head + "    targets: {cycle_time: 2 m}\n");
  EXPECT_EQ(e.field(), "runs[0].targets.cycle_time");
  e = error_of(head + "    targets: {timed_out_waits: 0.5}\n");
  EXPECT_EQ(e.field(), "runs[0].targets.timed_out_waits");
  e = error_of(head + "    targets: {overload_cycles: -3}\n");
  EXPECT_EQ(e.field(), "runs[0].targets.overload_cycles");
  const auto suite = offline::parse_suite(
      head + "    scaling: none\n    sway_damping: true\n    wait_swing: 3 deg\n", "ok.yaml",
      kReplays);
  EXPECT_EQ(suite.runs[0].scaling, control::ScalingMode::kNone);
  EXPECT_TRUE(*suite.runs[0].sway_damping);
  EXPECT_DOUBLE_EQ(suite.runs[0].wait_swing_rad, 3.0 * M_PI / 180.0);
  EXPECT_EQ(suite.runs[0].name(), "demo.csv @default (scaling none)");
}

TEST(ScenarioSuite, AWaitingRunMissesItsCycleTimeAndTimeoutTargets) {
  auto suite = offline::parse_suite(
      "format: craneassist-suite/1\nruns:\n  - replay: loading/near.csv\n    sway_damping: false\n"
      "    targets: {cycle_time: 40 s, timed_out_waits: 0, residual_swing: 1 deg}\n",
      "tight.yaml", kReplays);
  const auto out = offline::run_suite_run(config::default_crane_config(), suite.runs[0], "", {});
  EXPECT_GT(out.summary.waits.waits, 0);
  ASSERT_EQ(out.missed.size(), 3u);
  EXPECT_NE(out.missed[0].find("residual swing"), std::string::npos) << out.missed[0];
  EXPECT_NE(out.missed[1].find("cycle time"), std::string::npos) << out.missed[1];
  EXPECT_NE(out.missed[2].find("timed-out waits"), std::string::npos) << out.missed[2];
}

// Machine variants (docs/suite-format.md#machine-variants): the shipped file loads against the
// K70M, its fields reach the simulated machine, its targets replace the suite's; mistakes are
// named by file, line and field.
TEST(ScenarioSuite, MachineVariantsLoadApplyAndNameTheirMistakes) {
  const auto cfg = config::default_crane_config();
  const auto variants = offline::load_variants(
      std::filesystem::path(CRANEASSIST_SOURCE_DIR) / "examples/machines/variants.yaml", cfg);
  ASSERT_GE(variants.size(), 10u);
  EXPECT_EQ(variants.front().name, "model");
  for (const auto& v : variants.front().valves) EXPECT_TRUE(std::isnan(v.time_constant_s));
  ASSERT_TRUE(variants.front().targets.direction_error_p95_rad);
  EXPECT_NEAR(*variants.front().targets.direction_error_p95_rad, 2.0 * M_PI / 180.0, 1e-12);

  const auto parsed = offline::parse_variants(
      "format: craneassist-variants/1\nvariants:\n  - name: fast\n    simulation:\n"
      "      valves: {time_constant: 25 ms, lift: {gain: 0.8}}\n"
      "      feedback: {jitter: 5 ms}\n    targets: {stop_timeouts: 0}\n",
      "v.yaml", cfg);
  ASSERT_EQ(parsed.size(), 1u);
  const auto machine = parsed[0].apply(cfg);
  EXPECT_DOUBLE_EQ(machine.simulation.valves[0].time_constant_s, 0.025);
  EXPECT_DOUBLE_EQ(machine.simulation.valves[1].gain, 0.8);
  EXPECT_DOUBLE_EQ(machine.simulation.valves[2].gain, 1.0);
  EXPECT_DOUBLE_EQ(machine.simulation.joints.feedback_jitter_s, 0.005);
  EXPECT_EQ(parsed[0].targets.stop_timeouts, 0);
  EXPECT_TRUE(std::isnan(cfg.simulation.valves[0].time_constant_s)) << "the base untouched";

  auto error = [&](const std::string& yaml) {
    return test::thrown_error<config::ConfigError>(
        [&] { offline::parse_variants(yaml, "v.yaml", cfg); }, "no error for:\n" + yaml);
  };
  const std::string head = "format: craneassist-variants/1\nvariants:\n";
  auto e = error(head + "  - name: a\n    simulation: {valves: {boom: {gain: 2}}}\n");
  EXPECT_EQ(e.file(), "v.yaml");
  EXPECT_EQ(e.line(), 4);
  EXPECT_EQ(e.field(), "variants[0].simulation.valves.boom");
  EXPECT_EQ(error(head + "  - name: a\n    simulation: {step: 1 ms}\n").field(),
            "variants[0].simulation.step");
  EXPECT_EQ(error(head + "  - name: a\n  - name: a\n").field(), "variants[1].name");
  EXPECT_EQ(error("format: craneassist-variants/2\nvariants:\n  - name: a\n").field(), "format");
  EXPECT_EQ(error(head + "  - name: a\n    targets: {direction_error_p95: 2 m}\n").field(),
            "variants[0].targets.direction_error_p95");
}
