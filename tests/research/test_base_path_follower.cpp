// Flow-bounded path following of the wheeled base (paths/base_path_follower.hpp,
// docs/mobile.md) on the simulated base (sim_backend/mobile_base_sim.hpp): the composite Bezier
// path, the sum of the hub-motor flows never above Q_max on random paths, the closed loop
// converging from an off-path start, the slow-down by delta and the per-motor speed limit.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "craneassist/config/base_config.hpp"
#include "craneassist/paths/base_path_follower.hpp"
#include "craneassist/paths/planar_path.hpp"
#include "craneassist/sim_backend/mobile_base_sim.hpp"

namespace {

using namespace craneassist;

config::BaseConfig shipped() {
  return config::load_base_config(std::string(CRANEASSIST_SOURCE_DIR) +
                                  "/config/machines/mobile_base.yaml");
}

paths::BaseFollowerConfig follower_config(const config::BaseConfig& c, double offset) {
  paths::BaseFollowerConfig f;
  f.k1_1_m = c.following.k1_1_m;
  f.k2 = c.following.k2;
  f.k3_1_m = c.following.k3_1_m;
  f.epsilon_m = c.following.epsilon_m;
  f.tool_offset_m = offset;
  f.period_s = 0.01;
  return f;
}

// The pose `along`, `left` from the platform's reference at s = 0, turned by `heading`.
dynamics::BasePose start_pose(const paths::CompositeBezierPath& path, double offset, double along,
                              double left, double heading) {
  paths::OffsetReference r;
  paths::offset_reference(path, offset, 0.0, r);
  const double c = std::cos(r.phi_rad), s = std::sin(r.phi_rad);
  return {r.platform.x() + c * along - s * left, r.platform.y() + s * along + c * left,
          r.phi_rad + heading};
}

struct BaseRun {
  double peak_flow_ratio = 0.0;            // measured, of the lagged motion
  double peak_commanded_flow_ratio = 0.0;  // of the commands
  double final_lateral_m = 1e9, final_heading_rad = 1e9;
  double max_lateral_after_m = 0.0;  // after `settle_s`
  double finished_at_s = -1.0;
  double peak_steer_rad = 0.0;
};

BaseRun run(const dynamics::MobileBaseModel& model, const paths::CompositeBezierPath& path,
            const paths::BaseFollowerConfig& fc, const dynamics::BasePose& start,
            double settle_s = 1e9, double delta = 1.0, double max_s = 1000.0) {
  paths::BasePathFollower follower(model, path, fc);
  sim_backend::MobileBaseSim sim(model, start);
  paths::BaseFollowerOutput out;
  BaseRun r;
  for (int k = 0; k * fc.period_s < max_s; ++k) {
    const double t = k * fc.period_s;
    follower.update({sim.state().pose, delta, 0.0}, out);
    sim.command({out.v_m_s, out.omega_rad_s});
    sim.advance(fc.period_s);
    r.peak_commanded_flow_ratio =
        std::max(r.peak_commanded_flow_ratio, out.wheels.flow_sum_m3_s / model.pump_max_flow_m3_s);
    r.peak_flow_ratio =
        std::max(r.peak_flow_ratio, sim.state().wheels.flow_sum_m3_s / model.pump_max_flow_m3_s);
    for (const double psi : sim.state().wheels.steer_rad) {
      r.peak_steer_rad = std::max(r.peak_steer_rad, std::abs(psi));
    }
    if (t > settle_s && !out.finished) {
      r.max_lateral_after_m = std::max(r.max_lateral_after_m, std::abs(out.e_y_m));
    }
    if (out.finished) {
      r.finished_at_s = t;
      r.final_lateral_m = std::abs(out.e_y_m);
      r.final_heading_rad = std::abs(out.e_phi_rad);
      break;
    }
  }
  return r;
}

}  // namespace

TEST(CompositeBezierPath, PassesTheViaPointsC2) {
  const std::vector<Eigen::Vector2d> via = {{0, 0}, {8, 0}, {15, 4}, {18, 11}, {24, 15}, {32, 15}};
  const paths::CompositeBezierPath path(via);
  ASSERT_EQ(path.segments(), 5);
  paths::CompositeBezierPath::Point a, b;
  for (int i = 0; i <= 5; ++i) {
    path.evaluate(i / 5.0, a);
    EXPECT_NEAR((a.p - via[static_cast<std::size_t>(i)]).norm(), 0.0, 1e-12);
  }
  // Continuous position, tangent and second derivative at the junctions.
  for (int i = 1; i < 5; ++i) {
    path.evaluate(i / 5.0 - 1e-9, a);
    path.evaluate(i / 5.0 + 1e-9, b);
    EXPECT_NEAR((a.p - b.p).norm(), 0.0, 1e-6);
    EXPECT_NEAR((a.d1 - b.d1).norm(), 0.0, 1e-5);
    EXPECT_NEAR((a.d2 - b.d2).norm(), 0.0, 1e-3 * b.d2.norm() + 1e-5);
  }
  // The derivatives against finite differences.
  for (double s : {0.13, 0.5, 0.77}) {
    const double h = 1e-6;
    path.evaluate(s - h, a);
    path.evaluate(s + h, b);
    paths::CompositeBezierPath::Point m;
    path.evaluate(s, m);
    EXPECT_NEAR(((b.p - a.p) / (2 * h) - m.d1).norm(), 0.0, 1e-4);
    EXPECT_NEAR(((b.d1 - a.d1) / (2 * h) - m.d2).norm(), 0.0, 1e-2);
  }
  // A straight line of two points: the length is the distance.
  const paths::CompositeBezierPath line({{0, 0}, {3, 4}});
  EXPECT_NEAR(line.length_m(), 5.0, 1e-9);
}

TEST(CompositeBezierPath, OffsetPathKeepsItsDistanceAndHeading) {
  const paths::CompositeBezierPath path({{0, 0}, {8, 0}, {15, 4}, {18, 11}, {24, 15}});
  paths::OffsetReference r, r2;
  for (double s = 0.0; s <= 1.0; s += 0.01) {
    paths::offset_reference(path, 4.5, s, r);
    EXPECT_NEAR((r.tool - r.platform).norm(), 4.5, 1e-9);
    // The tool is left of the platform's heading.
    const Eigen::Vector2d left(-std::sin(r.phi_rad), std::cos(r.phi_rad));
    EXPECT_NEAR((r.tool - r.platform).dot(left), 4.5, 1e-9);
    // v' is the platform path's own speed per unit s.
    const double h = 1e-6;
    paths::offset_reference(path, 4.5, std::min(1.0, s + h), r2);
    if (s + h <= 1.0) {
      EXPECT_NEAR((r2.platform - r.platform).norm() / h, r.v_prime_m, 1e-3 * r.v_prime_m);
    }
  }
  // Offset into a tight turn: a cusp.
  EXPECT_LE(paths::check_offset_path(path, -12.0).min_v_prime_m, 0.0);
}

TEST(BasePathFollower, FlowBoundNeverExceededOnRandomPaths) {
  const config::BaseConfig cfg = shipped();
  const dynamics::MobileBaseModel& model = cfg.model;
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> turn(-0.9, 0.9), length(4.0, 10.0), unit(-1.0, 1.0);
  int runs = 0;
  for (int trial = 0; trial < 60 && runs < 12; ++trial) {
    std::vector<Eigen::Vector2d> via = {{0, 0}};
    double heading = 0.0;
    for (int i = 0; i < 5; ++i) {
      heading += turn(rng);
      const double l = length(rng);
      via.push_back(via.back() + l * Eigen::Vector2d(std::cos(heading), std::sin(heading)));
    }
    const paths::CompositeBezierPath path(via);
    const double offset = 3.0 * unit(rng);
    const auto check = paths::check_offset_path(path, offset);
    if (!(check.min_v_prime_m > 0.0) ||
        check.max_curvature_1_m > dynamics::max_curvature_1_m(model)) {
      continue;  // the platform cannot follow it: not a path for this test
    }
    const auto start =
        start_pose(path, offset, -0.5 * std::abs(unit(rng)), 1.5 * unit(rng), 0.3 * unit(rng));
    const BaseRun r = run(model, path, follower_config(cfg, offset), start);
    ++runs;
    EXPECT_GT(r.finished_at_s, 0.0);
    EXPECT_LE(r.peak_commanded_flow_ratio, 1.0 + 1e-9);
    EXPECT_LE(r.peak_flow_ratio, 1.0 + 1e-9);
    // And the bound is what sets the speed: the pump is used, not left idle.
    EXPECT_GT(r.peak_flow_ratio, 0.99);
    EXPECT_LE(r.peak_steer_rad, model.steer_max_rad + 1e-9);
  }
  EXPECT_GE(runs, 8);
}

TEST(BasePathFollower, ConvergesFromAnOffPathStart) {
  const config::BaseConfig cfg = shipped();
  const paths::CompositeBezierPath path({{0, 0}, {8, 0}, {15, 4}, {18, 11}, {24, 15}, {32, 15}});
  const double offset = cfg.following.tool_offset_m;
  // The start of `craneassist research follow`: 0.5 m behind, 1 m right of the path, 8.6 deg off.
  for (const auto& [along, left, heading] :
       {std::tuple{-0.5, -1.0, 0.15}, std::tuple{0.0, 1.5, -0.3}, std::tuple{-1.0, 0.5, 0.4}}) {
    const auto start = start_pose(path, offset, along, left, heading);
    const BaseRun r = run(cfg.model, path, follower_config(cfg, offset), start, 30.0);
    ASSERT_GT(r.finished_at_s, 0.0);
    EXPECT_LT(r.max_lateral_after_m, 0.1) << along << " " << left << " " << heading;
    EXPECT_LT(r.final_lateral_m, 0.02);
    EXPECT_LT(r.final_heading_rad, 0.02);
  }
}

TEST(BasePathFollower, TrackingFactorAndMotorLimitSlowIt) {
  config::BaseConfig cfg = shipped();
  const paths::CompositeBezierPath path({{0, 0}, {10, 0}, {20, 5}});
  const auto fc = follower_config(cfg, 0.0);
  const auto start = start_pose(path, 0.0, 0.0, 0.0, 0.0);
  const BaseRun full = run(cfg.model, path, fc, start);
  const BaseRun half = run(cfg.model, path, fc, start, 1e9, 0.5);
  ASSERT_GT(full.finished_at_s, 0.0);
  ASSERT_GT(half.finished_at_s, 0.0);
  EXPECT_NEAR(half.finished_at_s / full.finished_at_s, 2.0, 0.05);
  EXPECT_LT(half.peak_flow_ratio, 0.51);
  // A motor limit below the flow bound's speed: it sets the speed instead.
  cfg.model.motor_speed_max_rad_s = 0.5 * 0.326 / 0.35 * 17.7;  // half the flow-bound speed
  paths::BasePathFollower follower(cfg.model, path, fc);
  paths::BaseFollowerOutput out;
  follower.update({start, 1.0, 0.0}, out);
  EXPECT_EQ(out.limit, scaling::BaseLimit::kMotorSpeed);
  for (const double n : out.wheels.motor_speed_rad_s) {
    EXPECT_LE(std::abs(n), cfg.model.motor_speed_max_rad_s * (1 + 1e-9));
  }
  // The arm's flow counted against the pump when they share it.
  cfg.model.motor_speed_max_rad_s = 0.0;
  paths::BasePathFollower shared(cfg.model, path, fc);
  shared.set_arm_shares_pump(true);
  shared.update({start, 1.0, 0.75 * cfg.model.pump_max_flow_m3_s}, out);
  EXPECT_NEAR(out.wheels.flow_sum_m3_s, 0.25 * cfg.model.pump_max_flow_m3_s, 1e-12);
}

TEST(CompositeBezierPath, TheOffsetCheckSeesATightTurnOnALongPath) {
  // 6000 via points 1 m apart along x, one of them 0.3 m aside: a turn within a few segments of
  // thousands, on the tool path itself (offset 0).
  std::vector<Eigen::Vector2d> via;
  for (int i = 0; i < 6000; ++i) via.emplace_back(i, i == 3000 ? 0.3 : 0.0);
  const paths::CompositeBezierPath path(via);
  const auto sharpest = [&](int samples) {  // the sharpest turn seen at `samples` even steps
    double kappa = 0.0;
    paths::OffsetReference r;
    for (int k = 0; k <= samples; ++k) {
      paths::offset_reference(path, 0.0, static_cast<double>(k) / samples, r);
      kappa = std::max(kappa, std::abs(r.omega_prime_rad / r.v_prime_m));
    }
    return kappa;
  };
  const double dense = sharpest(256 * path.segments());
  const paths::OffsetPathCheck check = paths::check_offset_path(path, 0.0);
  EXPECT_GT(dense, 0.5);
  EXPECT_GT(check.max_curvature_1_m, 0.95 * dense);
  EXPECT_NEAR(check.max_curvature_s * path.segments(), 3000.0, 0.5);
  // 4000 samples over the whole path (the check before it sampled every segment) miss it.
  EXPECT_LT(sharpest(4000), 0.65 * dense);  // 0.58 of it
}
