// The hanging grapple (docs/sway.md): its pendulum model, the simulator swinging it at that
// pendulum's frequency, the ZV shaper that damps it, and the config section.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "config_edit.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/pendulum.hpp"
#include "craneassist/scaling/scaling_filter.hpp"
#include "craneassist/scaling/sway_shaper.hpp"
#include "craneassist/scaling/swing_frequency.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

using namespace craneassist;

namespace {

const std::string kK70m = std::string(CRANEASSIST_SOURCE_DIR) + "/config/cranes/k70m.yaml";
constexpr double kPeriod = 0.01;

// A linear pendulum (swing x in rad) whose pivot stops from v0 as the jerk-limited scaling filter
// brings it to rest (jerk 4 m/s^3, deceleration 2 m/s^2, as the K70M's tip scaler), the filter's
// speed ZV-shaped or not: x'' + 2 zeta w x' + w^2 x = -a / L. Returns the swing amplitude once
// the pivot is at rest, the largest swing on the way, and when it came to rest.
struct Swing {
  double residual_rad = 0.0;
  double peak_rad = 0.0;
  double rest_time_s = 0.0;  // when the pivot came to rest
};

Swing pendulum_response(double v0, double omega_model, double omega_true, double zeta,
                        bool shaped) {
  const double length = 9.81 / (omega_true * omega_true);
  scaling::SwayShaper shaper(kPeriod, 3.0);
  scaling::ScalingFilter filter(scaling::ScalingFilterConfig{kPeriod, 4.0});
  // Moving at v0 for a long time: the shaper's history holds v0, the pendulum hangs still.
  for (int k = 0; k < 400; ++k) shaper.shape(Eigen::Vector3d(v0, 0, 0), omega_model, zeta);
  filter.reset({0.0, v0, 0.0, 0.0});
  double x = 0.0, xd = 0.0, speed = v0;
  Swing out;
  bool at_rest = false;
  for (int k = 0; k < 1500; ++k) {
    scaling::ScalingFilterState st;
    filter.update({0.0, -2.0, 1.0}, st);
    const double pivot =
        shaped ? shaper.shape(Eigen::Vector3d(st.sdot, 0, 0), omega_model, zeta).x() : st.sdot;
    const double a = (pivot - speed) / kPeriod;
    speed = pivot;
    // Ten substeps of the pendulum per cycle (semi-implicit Euler).
    for (int j = 0; j < 10; ++j) {
      const double h = kPeriod / 10.0;
      xd += h * (-2.0 * zeta * omega_true * xd - omega_true * omega_true * x - a / length);
      x += h * xd;
    }
    out.peak_rad = std::max(out.peak_rad, std::abs(x));
    if (!at_rest && speed == 0.0 && st.sdot == 0.0 && st.sddot == 0.0) {
      at_rest = true;
      out.rest_time_s = (k + 1) * kPeriod;
    }
    if (at_rest) {
      out.residual_rad =
          std::max(out.residual_rad, std::hypot(x, xd / (omega_true * std::sqrt(1 - zeta * zeta))));
    }
  }
  return out;
}

}  // namespace

TEST(SwayShaper, WithoutAPendulumTheGoalPassesUnchanged) {
  scaling::SwayShaper shaper(kPeriod, 2.0);
  const Eigen::Vector3d goal(0.3, -0.1, 0.2);
  EXPECT_EQ(shaper.shape(goal, 0.0, 0.05), goal);
  EXPECT_EQ(shaper.shape(goal, std::nan(""), 0.05), goal);
  EXPECT_EQ(scaling::SwayShaper::delay_s(0.0, 0.0), 0.0);
  EXPECT_NEAR(scaling::SwayShaper::delay_s(M_PI, 0.0), 1.0, 1e-12);  // half of a 2 s period
}

TEST(SwayShaper, SplitsAStepIntoTwoHalfAPeriodApart) {
  scaling::SwayShaper shaper(kPeriod, 2.0);
  // A damped period of 2 s: the second step 1 s (100 cycles) after the first.
  const double omega = M_PI / std::sqrt(1 - 0.01);
  const double k = std::exp(-0.1 * M_PI / std::sqrt(1 - 0.01));
  const Eigen::Vector3d step(1.0, 0.0, 0.0);
  for (int c = 0; c < 100; ++c) {
    EXPECT_NEAR(shaper.shape(step, omega, 0.1).x(), 1.0 / (1.0 + k), 1e-12) << c;
  }
  EXPECT_NEAR(shaper.shape(step, omega, 0.1).x(), 1.0, 1e-12);
  shaper.reset();
  EXPECT_NEAR(shaper.shape(step, omega, 0.1).x(), 1.0 / (1.0 + k), 1e-12);
}

TEST(SwayShaper, NeverFasterThanTheGoalsItBlends) {
  scaling::SwayShaper shaper(kPeriod, 2.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> goals;
  const int delay =
      static_cast<int>(std::lround(scaling::SwayShaper::delay_s(3.0, 0.05) / kPeriod));
  for (int c = 0; c < 1000; ++c) {
    goals.emplace_back(u(rng), u(rng), u(rng));
    const Eigen::Vector3d shaped = shaper.shape(goals.back(), 3.0, 0.05);
    const double past = c >= delay ? goals[static_cast<std::size_t>(c - delay)].norm() : 0.0;
    EXPECT_LE(shaped.norm(), std::max(goals.back().norm(), past) + 1e-12) << c;
  }
}

// The shaped stop leaves almost no swing where the unshaped one leaves it all, on a pendulum as
// slow as the K70M's grapple, with the frequency known and 10 % off.
TEST(SwayShaper, AShapedStopLeavesNoSwing) {
  const double omega = 3.6, zeta = 0.05;
  for (const double v0 : {0.3, 0.6, 1.0}) {
    const Swing free = pendulum_response(v0, omega, omega, zeta, false);
    const Swing exact = pendulum_response(v0, omega, omega, zeta, true);
    const Swing off = pendulum_response(v0, omega, 1.1 * omega, zeta, true);
    EXPECT_GT(free.residual_rad, 0.02 * v0) << v0;
    EXPECT_LT(exact.residual_rad, 0.03 * free.residual_rad) << v0;
    EXPECT_LT(off.residual_rad, 0.25 * free.residual_rad) << v0;
    // Later at rest by the shaper's delay at most.
    EXPECT_LE(exact.rest_time_s,
              free.rest_time_s + scaling::SwayShaper::delay_s(omega, zeta) + kPeriod)
        << v0;
  }
}

TEST(GrapplePendulum, APointMassIsASimplePendulum) {
  dynamics::CraneModel m = config::load_crane_config(kK70m).model;
  for (auto& b : m.bodies) {
    if (b.name == "rotator and grapple") b.inertia_diag_kgm2.setZero();
  }
  m.grapple.com_below_m = m.grapple.load_below_m = 1.2;
  m.grapple.damping_n_m_s_rad = 0.0;
  const dynamics::Pendulum p = dynamics::grapple_pendulum(m, 500.0);
  EXPECT_NEAR(p.omega_rad_s, std::sqrt(9.81 / 1.2), 1e-9);
  EXPECT_EQ(p.zeta, 0.0);
  EXPECT_NEAR(p.period_s(), 2 * M_PI * std::sqrt(1.2 / 9.81), 1e-9);
  m.grapple.com_below_m = 0.0;  // rigid: nothing swings
  EXPECT_EQ(dynamics::grapple_pendulum(m, 500.0).omega_rad_s, 0.0);
}

TEST(GrapplePendulum, K70mLoadSlowsTheSwingTowardsThePointAtItsDepth) {
  const dynamics::CraneModel m = config::load_crane_config(kK70m).model;
  const dynamics::Pendulum empty = dynamics::grapple_pendulum(m, 0.0);
  const dynamics::Pendulum loaded = dynamics::grapple_pendulum(m, 800.0);
  // 180 kg at 0.7 m, 6.5 kg m^2 of its own; the load at 0.95 m.
  EXPECT_NEAR(empty.omega_rad_s, std::sqrt(9.81 * 180 * 0.7 / (180 * 0.49 + 6.5)), 1e-9);
  EXPECT_LT(loaded.omega_rad_s, empty.omega_rad_s);
  EXPECT_GT(loaded.omega_rad_s, std::sqrt(9.81 / 0.95));
  EXPECT_LT(loaded.zeta, empty.zeta);  // the same brake on a heavier pendulum
}

// The simulator's grapple, set swinging by a burst of the extension, swings at the model's
// frequency and its link damps it; without a grapple section nothing measures a swing.
TEST(HangingGrapple, SimulatorSwingsAtThePendulumsFrequency) {
  const config::CraneConfig cfg = config::load_crane_config(kK70m);
  for (const double load_kg : {0.0, 600.0}) {
    sim_backend::SimSettings settings;
    settings.q_initial = cfg.simulation.q_initial;
    sim_backend::SimBackend sim(cfg.model, settings);
    sim.set_payload_mass(load_kg);
    valves::ValveCommand cmd;
    cmd.spool = dynamics::JointVector::Zero(cfg.model.dof());
    valves::MachineState state;
    std::vector<double> t, radial;
    double first_peak = 0.0, last_peak = 0.0;
    for (int c = 0; c < 1000; ++c) {
      cmd.spool[3] = c < 60 ? 0.9 : 0.0;  // the extension out for 0.6 s
      sim.write(cmd);
      sim.advance(kPeriod);
      ASSERT_EQ(sim.read(state), valves::BackendStatus::kOk);
      ASSERT_TRUE(std::isfinite(state.swing_radial_rad));
      EXPECT_NEAR(state.swing_rad, std::hypot(state.swing_radial_rad, state.swing_tangential_rad),
                  1e-3);
      if (c >= 200) {  // the boom at rest (the valves' delay and lag passed)
        t.push_back(state.t_s);
        radial.push_back(state.swing_radial_rad);
        if (c < 400) first_peak = std::max(first_peak, std::abs(state.swing_radial_rad));
        if (c >= 800) last_peak = std::max(last_peak, std::abs(state.swing_radial_rad));
      }
    }
    EXPECT_GT(first_peak, 0.02) << load_kg;  // over a degree
    EXPECT_LT(last_peak, first_peak) << load_kg;
    // Zero crossings, interpolated: half a period apart.
    std::vector<double> crossings;
    for (std::size_t k = 1; k < radial.size(); ++k) {
      if ((radial[k - 1] < 0.0) != (radial[k] < 0.0)) {
        crossings.push_back(t[k - 1] +
                            (t[k] - t[k - 1]) * radial[k - 1] / (radial[k - 1] - radial[k]));
      }
    }
    ASSERT_GE(crossings.size(), 4u) << load_kg;
    const double measured =
        2.0 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
    const double model = dynamics::grapple_pendulum(cfg.model, load_kg).period_s();
    EXPECT_NEAR(measured, model, 0.03 * model) << load_kg;
    std::printf("[ figures  ] swing period with %.0f kg: simulated %.3f s, model %.3f s\n", load_kg,
                measured, model);
  }
}

TEST(HangingGrapple, ARigidTipMeasuresNoSwing) {
  config::CraneConfig cfg = config::load_crane_config(kK70m);
  cfg.model.grapple = {};
  sim_backend::SimSettings settings;
  settings.q_initial = cfg.simulation.q_initial;
  sim_backend::SimBackend sim(cfg.model, settings);
  valves::MachineState state;
  sim.advance(kPeriod);
  ASSERT_EQ(sim.read(state), valves::BackendStatus::kOk);
  EXPECT_TRUE(std::isnan(state.swing_rad));
  EXPECT_TRUE(std::isnan(state.swing_radial_rad));
}

TEST(CraneConfig, GrappleSection) {
  const config::CraneConfig cfg = config::load_crane_config(kK70m);
  EXPECT_DOUBLE_EQ(cfg.model.grapple.com_below_m, 0.7);
  EXPECT_DOUBLE_EQ(cfg.model.grapple.load_below_m, 0.95);
  EXPECT_DOUBLE_EQ(cfg.model.grapple.damping_n_m_s_rad, 40.0);
  EXPECT_TRUE(cfg.scaling.sway_damping);
  const auto bad_unit =
      test::crane_config_error_after_edit(kK70m, "damping: 40 N*m*s/rad", "damping: 40 N*s/m");
  EXPECT_NE(std::string(bad_unit.what()).find("grapple.damping"), std::string::npos)
      << bad_unit.what();
  const auto too_long =
      test::crane_config_error_after_edit(kK70m, "hanger_length: 0.7 m", "hanger_length: 70 m");
  EXPECT_NE(std::string(too_long.what()).find("grapple.hanger_length"), std::string::npos)
      << too_long.what();
  const auto bad_switch =
      test::crane_config_error_after_edit(kK70m, "sway_damping: true", "sway_damping: maybe");
  EXPECT_NE(std::string(bad_switch.what()).find("scaling.sway_damping"), std::string::npos)
      << bad_switch.what();
}

// The swing period from the swing sensor (scaling/swing_frequency.hpp): a free swing's period
// through the sensor's noise, and nothing from a driven swing, the noise alone or a gap.
namespace {

struct SwingSignal {
  double period_s = 2.3, amplitude_rad = 0.05, zeta = 0.02, noise_rad = 0.0002;
  double radial(double t) const {
    const double w = 2.0 * M_PI / period_s;
    return amplitude_rad * std::exp(-zeta * w * t) * std::sin(w * t);
  }
};

}  // namespace

TEST(SwingFrequency, MeasuresAFreeSwingsPeriodThroughTheNoise) {
  const SwingSignal s;
  const double model_period = 1.9;
  scaling::SwingFrequencyEstimator e;
  EXPECT_EQ(e.ratio(), 1.0);  // the model's until measured
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, s.noise_rad);
  for (int k = 0; k < 1500; ++k) {
    const double t = k * kPeriod;
    e.update(t, s.radial(t) + noise(rng), 0.5 * s.radial(t) + noise(rng), 0.0, model_period);
  }
  EXPECT_GE(e.measured(), 8);  // both axes, a period each
  EXPECT_NEAR(e.ratio(), model_period / s.period_s, 0.005 * model_period / s.period_s);
  EXPECT_NEAR(e.last_period_s(), s.period_s, 0.01);
}

TEST(SwingFrequency, NothingFromADrivenSwingTheNoiseAloneAGapOrAnImplausiblePeriod) {
  const SwingSignal s;
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, 0.001);  // 0.06 deg
  // The tip's reference accelerating throughout: the swing is driven, not free.
  scaling::SwingFrequencyEstimator driven;
  // The sensor's noise alone, no swing.
  scaling::SwingFrequencyEstimator quiet;
  // A gap in the measurement every second.
  scaling::SwingFrequencyEstimator gaps;
  // The model's period so far off that the measured one is not believed.
  scaling::SwingFrequencyEstimator implausible;
  for (int k = 0; k < 1500; ++k) {
    const double t = k * kPeriod;
    driven.update(t, s.radial(t), s.radial(t), 0.2, 1.9);
    quiet.update(t, noise(rng), noise(rng), 0.0, 1.9);
    const bool gap = k % 100 == 50;
    gaps.update(t, gap ? NAN : s.radial(t), gap ? NAN : s.radial(t), 0.0, 1.9);
    implausible.update(t, s.radial(t), s.radial(t), 0.0, 0.9);
  }
  EXPECT_EQ(driven.measured(), 0);
  EXPECT_EQ(quiet.measured(), 0);
  EXPECT_EQ(gaps.measured(), 0);
  EXPECT_EQ(implausible.measured(), 0);
  for (const auto* e : {&driven, &quiet, &gaps, &implausible}) EXPECT_EQ(e->ratio(), 1.0);
}

TEST(SwingFrequency, TheNewestPeriodsCountAndResetForgets) {
  scaling::SwingFrequencyEstimator e;
  double t = 0.0;
  const auto swing = [&](double period, int cycles) {
    for (int k = 0; k < cycles; ++k, t += kPeriod) {
      e.update(t, 0.05 * std::sin(2.0 * M_PI * t / period), NAN, 0.0, 2.0);
    }
  };
  swing(2.5, 1200);
  EXPECT_NEAR(e.ratio(), 2.0 / 2.5, 0.005);
  swing(1.6, 700);  // the grapple changed (a longer log): the newest two periods count
  EXPECT_NEAR(e.ratio(), 2.0 / 1.6, 0.02);
  e.reset();
  EXPECT_EQ(e.measured(), 0);
  EXPECT_EQ(e.ratio(), 1.0);
}
