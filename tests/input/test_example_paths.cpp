// The paper-000 test paths shipped in examples/paths/ for the K70M: their durations, lengths and
// peak speeds, and that the crane can follow every point with freedom left in the extension, so
// that a redundancy planner has room to optimise.
#include <gtest/gtest.h>

#include <string>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/inverse_kinematics.hpp"
#include "craneassist/input/prescribed_path.hpp"

namespace {

using craneassist::input::PrescribedPath;
namespace dyn = craneassist::dynamics;

const dyn::CraneModel& k70m() {
  static const dyn::CraneModel model = craneassist::config::default_crane_config().model;
  return model;
}

PrescribedPath example(const std::string& name) {
  return PrescribedPath::load_file(std::string(CRANEASSIST_SOURCE_DIR) + "/examples/paths/" + name);
}

// Longest interval of extensions q4 (on a 1 cm grid over the joint range) for which the tip
// position is reachable with every joint within its limits.
double feasible_extension_range_m(const Eigen::Vector3d& tip_m) {
  const dyn::DhJoint& extension = k70m().joints[3];
  constexpr int kSteps = 370;
  double best_m = 0.0;
  int run_start = -1;
  dyn::JointVector q;
  for (int k = 0; k <= kSteps + 1; ++k) {
    const double q4 = extension.q_min + (extension.q_max - extension.q_min) * k / kSteps;
    const bool ok =
        k <= kSteps && dyn::solve_given_extension(k70m(), tip_m, q4, q) == dyn::IkStatus::kOk;
    if (ok && run_start < 0) run_start = k;
    if (!ok && run_start >= 0) {
      best_m = std::max(best_m, (extension.q_max - extension.q_min) * (k - 1 - run_start) / kSteps);
      run_start = -1;
    }
  }
  return best_m;
}

// Smallest feasible extension range over samples every 0.05 s.
double worst_feasible_extension_range_m(const PrescribedPath& path) {
  double worst_m = 1e9;
  const int samples = static_cast<int>(std::round(path.duration_s() / 0.05));
  for (int k = 0; k <= samples; ++k) {
    const double t = path.start_time_s() + path.duration_s() * k / samples;
    worst_m = std::min(worst_m, feasible_extension_range_m(path.at(t).p_m));
  }
  return worst_m;
}

TEST(ExamplePaths, FeasibilityCheckCanFail) {
  ASSERT_TRUE(dyn::is_loader_structure(k70m()));
  EXPECT_GT(feasible_extension_range_m({5.0, 0.0, 0.0}), 3.0);
  EXPECT_EQ(feasible_extension_range_m({0.5, 1.0, 0.0}), 0.0);        // too close to the pillar
  EXPECT_EQ(feasible_extension_range_m({9.5, 1.0, 0.0}), 0.0);        // out of reach
  EXPECT_LT(feasible_extension_range_m({6.0, 6.0, 0.0}), 0.2 * 3.7);  // high up, little freedom
}

struct Expected {
  const char* file;
  PrescribedPath::Interpolation interpolation;
  double duration_s, length_m, length_tolerance_m, peak_speed_m_s, peak_tolerance_m_s;
};

TEST(ExamplePaths, Paper000PathsAreFeasibleWithFreedomInTheExtension) {
  using I = PrescribedPath::Interpolation;
  const Expected expected[] = {
      {"horizontal.csv", I::kQuinticLine, 10.0, 3.2, 1e-9, 0.60, 1e-9},
      {"vertical.csv", I::kQuinticLine, 6.0, 3.04, 1e-9, 0.95, 1e-9},
      {"half_cycle.csv", I::kClampedCubicSpline, 15.0, 7.80, 0.01, 0.75, 0.02},
  };
  const double extension_range_m = k70m().joints[3].q_max - k70m().joints[3].q_min;
  for (const Expected& e : expected) {
    SCOPED_TRACE(e.file);
    const PrescribedPath path = example(e.file);
    EXPECT_EQ(path.interpolation(), e.interpolation);
    EXPECT_NEAR(path.duration_s(), e.duration_s, 1e-12);
    EXPECT_NEAR(path.length_m(), e.length_m, e.length_tolerance_m);
    EXPECT_NEAR(path.peak_speed_m_s(), e.peak_speed_m_s, e.peak_tolerance_m_s);
    EXPECT_GE(worst_feasible_extension_range_m(path), 0.2 * extension_range_m);
  }
}

TEST(ExamplePaths, StraightPathsRunAlongTheirAxis) {
  const PrescribedPath horizontal = example("horizontal.csv");
  const Eigen::Vector3d dh = horizontal.via_points_m()[1] - horizontal.via_points_m()[0];
  EXPECT_NEAR(std::abs(dh.x()), dh.norm(), 1e-12);
  const PrescribedPath vertical = example("vertical.csv");
  const Eigen::Vector3d dv = vertical.via_points_m()[1] - vertical.via_points_m()[0];
  EXPECT_NEAR(std::abs(dv.y()), dv.norm(), 1e-12);
  // The half-cycle starts behind the slew axis, raised, and ends lower, in front.
  const PrescribedPath half = example("half_cycle.csv");
  EXPECT_LT(half.via_points_m().front().x(), 0.0);
  EXPECT_GT(half.via_points_m().back().x(), 0.0);
  EXPECT_GT(half.via_points_m().front().y(), half.via_points_m().back().y());
}

}  // namespace
