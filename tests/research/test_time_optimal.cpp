// The time-optimal bound (paths/time_optimal.hpp) against closed forms, and the bound tool's
// drive of paper 000's paths (app/path_bound.hpp): the controller stays on the path, arrives,
// and its time is measured against the bound.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/paths/time_optimal.hpp"
#include "craneassist/studies/path_bound.hpp"

using namespace craneassist;
using dynamics::JointVector;

namespace {

const std::string kSource = CRANEASSIST_SOURCE_DIR;

// A straight joint path of length L: the slew alone at rate `rate` per unit s (its cylinder arm
// from the model), every sample at the crane's start pose, so that the speed caps are uniform.
std::vector<paths::PathSample> slew_path(const dynamics::CraneModel& model, double length_m,
                                         double ds_m, double rate) {
  std::vector<paths::PathSample> samples;
  const JointVector q = JointVector::Zero(4);
  const auto n = static_cast<int>(std::lround(length_m / ds_m));
  for (int k = 0; k <= n; ++k) {
    paths::PathSample p;
    p.s = k * ds_m;
    p.q = q;
    p.q[0] = rate * p.s;
    p.q[1] = 0.35;
    p.q[2] = -1.2;
    p.q[3] = 1.0;
    p.geometry.f1 = JointVector::Zero(4);
    p.geometry.f1[0] = rate;
    p.geometry.f2 = JointVector::Zero(4);
    dynamics::cylinder_arms(model, p.q, p.geometry.dc_dq);
    p.geometry.d2c_dq2 = JointVector::Zero(4);
    samples.push_back(p);
  }
  return samples;
}

struct Bench {
  Bench() : cfg(config::default_crane_config()), terms(cfg.model) {
    settings.acceleration_max = 1.0;
    settings.deceleration_max = 2.0;
    settings.power_bound = scaling::PowerBound::kNone;
  }
  // The speed cap of a sample (pump flow, cylinder speed) and the acceleration the cylinders
  // allow, for the closed forms.
  double cap(const paths::PathSample& p) const {
    scaling::SpeedLimits limits;
    scaling::path_speed_limits(cfg.model, p.geometry, settings.flow_reserve, limits);
    return std::min(limits.sdot_flow, limits.sdot_cylinder);
  }
  config::CraneConfig cfg;
  dynamics::RigidBodyTerms terms;
  paths::TimeOptimalSettings settings;
};

// Rest to rest at A up, D down, cruise at v: the trapezoid (or the triangle when the path is too
// short to reach v).
double trapezoid_time(double length, double v, double a, double d) {
  const double ramps = v * v / (2 * a) + v * v / (2 * d);
  if (length >= ramps) return length / v + v / (2 * a) + v / (2 * d);
  const double peak = std::sqrt(2 * length * a * d / (a + d));
  return peak / a + peak / d;
}

}  // namespace

TEST(TimeOptimal, StraightPathIsTheTrapezoidOfItsBounds) {
  Bench s;
  // A slew rate per metre at which the path's own acceleration bounds bind, not the cylinder's.
  const auto samples = slew_path(s.cfg.model, 4.0, 1e-3, 0.5);
  const double v = s.cap(samples.front());
  ASSERT_GT(v, 0.5);
  ASSERT_LT(v, 3.0);
  const auto r = paths::time_optimal_profile(s.cfg.model, s.terms, samples, s.settings);
  ASSERT_TRUE(r.ok);
  const double expected = trapezoid_time(4.0, v, 1.0, 2.0);
  EXPECT_NEAR(r.time_s, expected, 2e-3 * expected);
  // Never above the cap, at rest at both ends, and the segments' times add up.
  double sum = 0.0;
  for (std::size_t k = 0; k < samples.size(); ++k) EXPECT_LE(r.sdot[k], v * (1 + 1e-12));
  EXPECT_EQ(r.sdot.front(), 0.0);
  EXPECT_EQ(r.sdot.back(), 0.0);
  for (const auto& seg : r.segments) sum += seg.time_s;
  EXPECT_NEAR(sum, r.time_s, 1e-9);
  // Accelerating, cruising at the cap, decelerating, in that order.
  EXPECT_EQ(r.segments.front().phase, paths::BoundPhase::kAccelerating);
  EXPECT_EQ(r.segments[r.segments.size() / 2].phase, paths::BoundPhase::kSpeedCap);
  EXPECT_EQ(r.segments.back().phase, paths::BoundPhase::kDecelerating);
  EXPECT_EQ(r.segments.front().limit, scaling::ActiveLimit::kNone);  // the path's bound
}

TEST(TimeOptimal, ShortPathIsTheTriangle) {
  Bench s;
  const auto samples = slew_path(s.cfg.model, 0.2, 1e-4, 0.05);
  const double v = s.cap(samples.front());
  ASSERT_GT(v * v / 2.0 + v * v / 4.0, 0.2) << "the cap must not be reached";
  const auto r = paths::time_optimal_profile(s.cfg.model, s.terms, samples, s.settings);
  ASSERT_TRUE(r.ok);
  EXPECT_NEAR(r.time_s, trapezoid_time(0.2, v, 1.0, 2.0), 2e-3 * r.time_s);
}

TEST(TimeOptimal, CylinderAccelerationBindsOnAFastJointPath) {
  Bench s;
  // A fast slew rate per metre: the slew cylinder's acceleration bound, a_max / (r f'), is
  // below the path's 1 m/s^2.
  const auto samples = slew_path(s.cfg.model, 2.0, 1e-3, 6.0);
  const double arm = std::abs(samples.front().geometry.dc_dq[0]) * 6.0;
  const double a_cyl = s.cfg.model.cylinders[0].a_max_m_s2 / arm;
  ASSERT_LT(a_cyl, 1.0);
  const double v = s.cap(samples.front());
  const auto r = paths::time_optimal_profile(s.cfg.model, s.terms, samples, s.settings);
  ASSERT_TRUE(r.ok);
  const double expected = trapezoid_time(2.0, v, a_cyl, std::min(a_cyl, 2.0));
  EXPECT_NEAR(r.time_s, expected, 3e-3 * expected);
  EXPECT_EQ(r.segments.front().limit, scaling::ActiveLimit::kCylinderAcceleration);
}

TEST(TimeOptimal, SampleCapsAreDipsTheProfileBrakesFor) {
  Bench s;
  auto samples = slew_path(s.cfg.model, 4.0, 1e-3, 0.5);
  const auto free = paths::time_optimal_profile(s.cfg.model, s.terms, samples, s.settings);
  for (std::size_t k = 1900; k <= 2100; ++k) {
    samples[k].sdot_cap = 0.2;
    samples[k].cap_name = "turning";
  }
  const auto dipped = paths::time_optimal_profile(s.cfg.model, s.terms, samples, s.settings);
  ASSERT_TRUE(dipped.ok);
  EXPECT_GT(dipped.time_s, free.time_s + 0.5);
  for (std::size_t k = 1900; k <= 2100; ++k) EXPECT_LE(dipped.sdot[k], 0.2 + 1e-12);
  // Braking into the dip at the deceleration bound: sdot^2 falls by 2 D ds per sample.
  const std::size_t k = 1850;
  const double slope =
      (dipped.sdot[k] * dipped.sdot[k] - dipped.sdot[k + 1] * dipped.sdot[k + 1]) / (2.0 * 1e-3);
  EXPECT_NEAR(slope, 2.0, 1e-6);
  EXPECT_EQ(dipped.segments[2000].phase, paths::BoundPhase::kSpeedCap);
}

TEST(TimeOptimal, APathThatCannotBeTraversedNamesWhere) {
  Bench s;
  auto samples = slew_path(s.cfg.model, 1.0, 1e-2, 0.05);
  samples[40].sdot_cap = samples[41].sdot_cap = 0.0;  // two samples in a row that admit no speed
  const auto r = paths::time_optimal_profile(s.cfg.model, s.terms, samples, s.settings);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.blocked_sample, 40);
  EXPECT_TRUE(r.segments.empty());
}

// The bound tool's drive of paper 000's horizontal path: the controller's reference stays on
// the line and stops at its end; its time lies above the bound (a lower bound), within the
// share the jerk bound costs, and with the jerk bound lifted within a few per cent of it.
TEST(PathBound, HorizontalPathDrivenByTheControllerNearTheBound) {
  auto cfg = config::default_crane_config();
  // The scaling's limits against their bound: the sway damping's shaping (half a swing period
  // at each start and stop, docs/sway.md) is not one of them.
  cfg.scaling.sway_damping = false;
  const auto path = input::PrescribedPath::load_file(kSource + "/examples/paths/horizontal.csv");
  studies::JointPathOptions options;
  const auto jp = studies::joint_path_for(cfg, path, options);
  EXPECT_TRUE(jp.online_arrived);
  EXPECT_LT(jp.online_deviation_m, 0.01);
  EXPECT_NEAR(jp.samples.back().s, path.length_m(), 0.015);
  const auto figures = studies::bound_figures(cfg, jp);
  ASSERT_TRUE(figures.bound.ok);
  const double ratio = jp.online_time_s / figures.bound.time_s;
  auto lifted = cfg;
  lifted.scaling.jerk_max_m_s3 *= 100.0;
  const auto jp_lifted = studies::joint_path_for(lifted, path, options);
  const auto lifted_figures = studies::bound_figures(lifted, jp_lifted);
  ASSERT_TRUE(lifted_figures.bound.ok);
  const double lifted_ratio = jp_lifted.online_time_s / lifted_figures.bound.time_s;
  std::printf(
      "[ figures  ] horizontal path: bound %.2f s, controller %.2f s (%.3f x); jerk "
      "lifted %.3f x\n",
      figures.bound.time_s, jp.online_time_s, ratio, lifted_ratio);
  EXPECT_GT(ratio, 1.0);
  EXPECT_LT(ratio, 1.10);
  EXPECT_GT(lifted_ratio, 0.98);
  EXPECT_LT(lifted_ratio, 1.05);
  // The drive keeps the cylinders within their speeds.
  EXPECT_LE(jp.online_speed_share, 1.0);
}

TEST(PathBound, StartOutOfReachIsAnError) {
  const auto cfg = config::default_crane_config();
  const auto path = input::PrescribedPath::parse("t,x,y,z\n0,30,0,0\n5,31,0,0\n", "far.csv");
  EXPECT_THROW(studies::joint_path_for(cfg, path, {}), std::runtime_error);
}
