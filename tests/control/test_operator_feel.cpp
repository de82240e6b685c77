// The operator-feel suite (examples/replays/suite.yaml, docs/scaling.md#operator-feel) on the
// simulated K70M: every run against its targets. The energy-optimal resolutions (the default)
// meet every target; the pseudo-inverse baselines never stall and keep the heavy lift on its
// line, and a joint of theirs reversing mid-motion through its valve's dead zone costs them up to
// twice the lateral target on the out-and-up push (a regression bound here; the figures are
// printed and documented).
#include <gtest/gtest.h>

#include <cstdio>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/offline/scenario_suite.hpp"

using namespace craneassist;

namespace {

const std::string kSource = CRANEASSIST_SOURCE_DIR;

struct Totals {
  double energy_j = 0.0;
  int runs = 0, missed = 0;
  double worst_lateral = 0.0;
};

Totals run_suite(const std::string& resolution, bool expect_every_target) {
  const auto suite = offline::load_suite(kSource + "/examples/replays/suite.yaml");
  const auto cfg = config::default_crane_config();
  offline::check_suite(suite, cfg);
  Totals t;
  for (const auto& run : suite.runs) {
    const auto out = offline::run_suite_run(cfg, run, resolution, {});
    const auto& s = out.summary;
    t.energy_j += s.energy_j;
    ++t.runs;
    t.missed += !out.ok();
    if (s.feel.one_line) t.worst_lateral = std::max(t.worst_lateral, s.feel.lateral_peak_m_s);
    std::string missed;
    for (const auto& m : out.missed) missed += m + "; ";
    if (expect_every_target) {
      EXPECT_TRUE(out.ok()) << run.name() << ": " << missed;
    } else {
      // Baselines: no stall, the heavy lift within power and on its line, lateral speed within
      // three times the target (the slew-rate limit on the spool commands slows the baselines'
      // section reversals: pinv-joint's sideways push reaches 0.072 m/s before a joint end, 0.023
      // without the limit; docs/valves.md).
      EXPECT_EQ(s.feel.stall_events, 0) << run.name();
      if (run.targets.peak_power_share) {
        EXPECT_LE(s.peak_power_w, *run.targets.peak_power_share * out.p_max_w) << run.name();
      }
      if (run.targets.direction_error_rad) {
        EXPECT_LE(s.max_direction_error_deg, *run.targets.direction_error_rad * 180.0 / M_PI)
            << run.name();
      }
      if (s.feel.one_line && run.targets.lateral_speed_m_s) {
        EXPECT_LE(s.feel.lateral_peak_m_s, 3.0 * *run.targets.lateral_speed_m_s) << run.name();
      }
    }
  }
  std::printf(
      "[ figures  ] suite, %s: %d runs, %d missed a target, worst lateral %.3f m/s, pump "
      "energy %.1f kJ\n",
      resolution.empty() ? "default" : resolution.c_str(), t.runs, t.missed, t.worst_lateral,
      t.energy_j / 1e3);
  return t;
}

}  // namespace

TEST(OperatorFeel, DefaultResolutionMeetsEveryTarget) {
  const Totals t = run_suite("", true);
  EXPECT_EQ(t.runs, 27);
}

TEST(OperatorFeel, MinFlowMeetsEveryTarget) {
  run_suite("min-flow", true);
}

TEST(OperatorFeel, PseudoInverseBaselinesNeverStall) {
  const Totals joint = run_suite("pinv-joint", false);
  const Totals actuator = run_suite("pinv-actuator", false);
  const Totals ls = run_suite("min-ls-power", true);
  // The energy-optimal default needs less pump energy over the suite than either baseline.
  EXPECT_LT(ls.energy_j, 0.95 * joint.energy_j);
  EXPECT_LT(ls.energy_j, 0.95 * actuator.energy_j);
}
