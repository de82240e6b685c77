// The sway damping tuned to the swing the machine's sensor measures (docs/sway.md, "Tuned to the
// measured swing"), on the simulated K70M whose grapple hangs twice as far as the controller's
// model says (a longer rotator link): the sensor's swing gives the true period, and the pushes
// after it add a fraction of the swing the model-tuned damping adds. Without a sensor the
// damping stays on the model. And the config's fields.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

#include "config_edit.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/replay_runner.hpp"
#include "craneassist/dynamics/pendulum.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

using namespace craneassist;

namespace {

const std::string kK70m = std::string(CRANEASSIST_SOURCE_DIR) + "/config/cranes/k70m.yaml";

// Each cycle's swing components (rad), by cycle.
struct Probe final : control::CycleObserver {
  std::vector<Eigen::Vector2d> swing;
  Probe() { swing.reserve(4000); }
  void on_cycle(const control::CycleRecord& c) noexcept override {
    swing.emplace_back(c.state.swing_radial_rad, c.state.swing_tangential_rad);
  }
};

struct Tuned {
  control::RunSummary summary;
  std::vector<Eigen::Vector2d> swing;
};

// The K70M whose simulated grapple hangs 1.4 m with the load 1.7 m below the link (the model:
// 0.7 and 0.95 m), with 400 kg, from the sway study's pose.
config::CraneConfig long_hanger(const std::string& sensor, bool measured) {
  std::string text = test::edited_text(kK70m, "  swing_sensor:\n",
                                       "  grapple: {hanger_length: 1.4 m, load_below: 1.7 m}\n"
                                       "  swing_sensor:\n");
  if (sensor == "none") {
    // The sensor's section, its two values with it, becomes `swing_sensor: none`.
    const auto at = text.find("  swing_sensor:\n");
    const auto end = text.find('\n', text.find("    resolution:", at));
    text.replace(at, end + 1 - at, "  swing_sensor: none\n");
  }
  if (!measured) {
    const auto p = text.find("  sway_damping: true");
    text.insert(p, "  sway_frequency: model\n");
  }
  auto cfg = config::parse_crane_config(text, "long_hanger.yaml");
  config::set_payload_mass(cfg.model, 400.0);
  cfg.simulation.q_initial = config::parse_joint_pose(
      cfg.model, "lift=35 deg, tilt=-110 deg, extension=1.8 m", cfg.simulation.q_initial);
  return cfg;
}

Tuned run(const config::CraneConfig& cfg, bool later_pushes) {
  // A push out and back, then (or not) two more after the grapple has swung freely for 6 s.
  const char* text = later_pushes ? "t,v_x,v_y,v_z\n0,0.5,0,0\n2,0,0,0\n8,-0.5,0,0\n10,0,0,0\n"
                                    "16,0.5,0,0\n18,0,0,0\n"
                                  : "t,v_x,v_y,v_z\n0,0.5,0,0\n2,0,0,0\n18,0,0,0\n";
  const auto replay = input::Replay::parse(text, "pushes.csv");
  sim_backend::SimBackend machine(cfg.model, offline::sim_settings(cfg));
  Probe probe;
  control::RunOptions options;
  options.settle_s = 6.0;
  options.observers.push_back(&probe);
  Tuned t;
  t.summary = control::run_replay(cfg, replay, machine, options, nullptr);
  t.swing = probe.swing;
  return t;
}

// The swing the two later pushes added, left once they are over (21 to 24 s): the runs with and
// without them differ by it (the swing is small, the pendulum nearly linear).
double added_swing(const config::CraneConfig& cfg) {
  const Tuned with = run(cfg, true), without = run(cfg, false);
  double worst = 0.0;
  for (std::size_t k = 2100; k < 2400 && k < with.swing.size() && k < without.swing.size(); ++k) {
    worst = std::max(worst, (with.swing[k] - without.swing[k]).norm());
  }
  return worst;
}

}  // namespace

TEST(SwayTuning, TheMeasuredSwingTunesTheDampingToTheGrappleTheCraneCarries) {
  const auto tuned_cfg = long_hanger("sensor", true);
  const auto model_cfg = long_hanger("sensor", false);
  ASSERT_TRUE(tuned_cfg.simulation.grapple.has_value());
  dynamics::CraneModel plant = tuned_cfg.model;
  plant.grapple = *tuned_cfg.simulation.grapple;
  const double true_period = dynamics::grapple_pendulum(plant, 400.0).period_s();
  const double model_period = dynamics::grapple_pendulum(tuned_cfg.model, 400.0).period_s();
  ASSERT_GT(true_period, 1.25 * model_period);

  const Tuned tuned = run(tuned_cfg, true);
  EXPECT_GT(tuned.summary.swing.measured_periods, 0);
  EXPECT_NEAR(tuned.summary.swing.model_period_s, model_period, 0.02 * model_period);
  EXPECT_NEAR(tuned.summary.swing.period_s, true_period, 0.03 * true_period);
  const Tuned on_model = run(model_cfg, true);
  EXPECT_EQ(on_model.summary.swing.measured_periods, 0);
  EXPECT_NEAR(on_model.summary.swing.period_s, on_model.summary.swing.model_period_s, 1e-12);
  EXPECT_NEAR(on_model.summary.swing.period_s, model_period, 0.02 * model_period);

  const double tuned_added = added_swing(tuned_cfg), model_added = added_swing(model_cfg);
  auto undamped_cfg = tuned_cfg;
  undamped_cfg.scaling.sway_damping = false;
  const double undamped_added = added_swing(undamped_cfg);
  std::printf(
      "[ figures  ] hanger twice the model's: periods %.2f s true, %.2f s model, %.2f s "
      "measured; two pushes add %.2f deg tuned, %.2f deg on the model, %.2f deg undamped\n",
      true_period, model_period, tuned.summary.swing.period_s, tuned_added * 180.0 / M_PI,
      model_added * 180.0 / M_PI, undamped_added * 180.0 / M_PI);
  EXPECT_GT(undamped_added, model_added);
  EXPECT_GT(model_added * 180.0 / M_PI, 1.0);
  EXPECT_LT(tuned_added, 0.25 * model_added);
}

TEST(SwayTuning, WithoutASwingSensorTheDampingStaysOnTheModel) {
  const auto cfg = long_hanger("none", true);
  EXPECT_FALSE(cfg.simulation.swing_sensor);
  const Tuned t = run(cfg, true);
  EXPECT_FALSE(t.summary.swing.measured);  // nothing measured the swing
  EXPECT_EQ(t.summary.swing.measured_periods, 0);
  EXPECT_NEAR(t.summary.swing.period_s, t.summary.swing.model_period_s, 1e-9);
  for (const auto& s : t.swing) EXPECT_TRUE(std::isnan(s.x()));
}

TEST(SwayTuning, ConfigFieldsAreCheckedAndNamed) {
  auto e = test::crane_config_error_after_edit(kK70m, "  sway_damping: true",
                                               "  sway_frequency: guessed\n  sway_damping: true");
  EXPECT_EQ(e.field(), "scaling.sway_frequency");
  EXPECT_NE(e.reason().find("expected model or measured, got 'guessed'"), std::string::npos);
  std::string text = test::read_text_file(kK70m);
  const auto at = text.find("  swing_sensor:\n");
  text.replace(at, text.find('\n', text.find("    resolution:", at)) + 1 - at,
               "  swing_sensor: broken\n");
  e = test::thrown_error<config::ConfigError>(
      [&] { config::parse_crane_config(text, "edited.yaml"); }, "no error");
  EXPECT_EQ(e.field(), "simulation.swing_sensor");
  EXPECT_NE(e.reason().find("expected none or {noise, resolution}, got 'broken'"),
            std::string::npos);
  e = test::crane_config_error_after_edit(kK70m, "    noise: 0.01 deg, assumed ",
                                          "    noise: 9 deg, assumed ");
  EXPECT_EQ(e.field(), "simulation.swing_sensor.noise");
  e = test::crane_config_error_after_edit(kK70m, "  swing_sensor:\n",
                                          "  grapple: {hanger_length: 2 kg}\n  swing_sensor:\n");
  EXPECT_EQ(e.field(), "simulation.grapple.hanger_length");
  e = test::crane_config_error_after_edit(kK70m, "  swing_sensor:\n",
                                          "  grapple: {reach: 1 m}\n  swing_sensor:\n");
  EXPECT_EQ(e.field(), "simulation.grapple.reach");
  // A plant grapple only where the model has one to differ from.
  const std::string rigid = std::string(CRANEASSIST_SOURCE_DIR) + "/config/cranes/planar_2r.yaml";
  std::string edited = test::read_text_file(rigid);
  const auto sim = edited.find("simulation:\n");
  ASSERT_NE(sim, std::string::npos);
  edited.insert(sim + std::string("simulation:\n").size(), "  grapple: {hanger_length: 1 m}\n");
  const auto error = test::thrown_error<config::ConfigError>(
      [&] { config::parse_crane_config(edited, "planar.yaml"); }, "no error");
  EXPECT_EQ(error.field(), "simulation.grapple");
}
