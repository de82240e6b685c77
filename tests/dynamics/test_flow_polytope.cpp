// The flow manipulability polytope (dynamics/flow_polytope.hpp) of the K70M and the planar 2R
// arm: the joint-velocity set's vertices against brute-force vertex enumeration of its
// inequalities, the tip polytope against sampled admissible joint velocities, the LP against the
// hull and against dense sampling of the null space, the volume against Monte Carlo, the speed
// along the controller's resolution against the scaling stage's own bound, and the degenerate
// cases (singular Jacobian, joints at their ends, every sign orthant).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

#include "allocation_counter.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/flow_polytope.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/null_space_resolution.hpp"
#include "craneassist/dynamics/redundancy.hpp"
#include "craneassist/scaling/flow_prescaling.hpp"
#include "craneassist/scaling/path_constraints.hpp"
#include "craneassist/scaling/tip_path.hpp"

using namespace craneassist;
using dynamics::FlowPolytope;
using dynamics::JointVector;
using dynamics::JointVelocitySet;
using dynamics::TaskJacobian;

namespace {

constexpr double kLpm = 1e-3 / 60.0;  // m^3/s per L/min

// The K70M; pump_lpm > 0 replaces its pump's 325 L/min (at which the flow barely limits: the
// four cylinders at full speed need about 310 L/min) by a smaller one.
dynamics::CraneModel k70m(double pump_lpm = 0.0) {
  dynamics::CraneModel m = config::default_crane_config().model;
  if (pump_lpm > 0.0) m.pump.max_flow_m3_s = pump_lpm * kLpm;
  return m;
}

dynamics::CraneModel planar_2r() {
  return config::load_crane_config(CRANEASSIST_SOURCE_DIR "/config/cranes/planar_2r.yaml").model;
}

// Each joint uniform in its range; with probability at_end a joint sits exactly at an end.
JointVector random_pose(const dynamics::CraneModel& m, std::mt19937& rng, double at_end = 0.0,
                        double margin = 0.0) {
  JointVector q(m.dof());
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < m.dof(); ++i) {
    const auto& j = m.joints[i];
    const double lo = j.q_min + margin * (j.q_max - j.q_min);
    const double hi = j.q_max - margin * (j.q_max - j.q_min);
    q[i] = lo + unit(rng) * (hi - lo);
    const double e = unit(rng);
    if (e < 0.5 * at_end) q[i] = j.q_min;
    if (e > 1.0 - 0.5 * at_end) q[i] = j.q_max;
  }
  return q;
}

Eigen::Vector3d random_direction(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Vector3d u(n(rng), n(rng), n(rng));
  return u.normalized();
}

struct Pose {
  JointVector q, arms;
  TaskJacobian jacobian;
  JointVelocitySet set;
};

Pose pose_of(const dynamics::CraneModel& m, const JointVector& q,
             const dynamics::FlowPolytopeSettings& settings = {}) {
  Pose p;
  p.q = q;
  dynamics::cylinder_arms(m, q, p.arms);
  dynamics::KinematicsData kin;
  dynamics::tip_jacobian(m, kin, q, p.jacobian);
  dynamics::joint_velocity_set(m, q, p.arms, settings, p.set);
  return p;
}

// A random joint-velocity set for n joints: bounds, flow weights (some zero bounds: joints at an
// end) and a flow limit between a tenth and all of the full-speed demand.
JointVelocitySet random_set(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.1, 1.0);
  JointVelocitySet s;
  s.qdot_min.resize(n);
  s.qdot_max.resize(n);
  s.flow_positive_m3.resize(n);
  s.flow_negative_m3.resize(n);
  double full = 0.0;
  for (int i = 0; i < n; ++i) {
    s.qdot_max[i] = u(rng);
    s.qdot_min[i] = -u(rng);
    if (u(rng) < 0.2) s.qdot_max[i] = 0.0;
    if (u(rng) < 0.2) s.qdot_min[i] = 0.0;
    s.flow_positive_m3[i] = u(rng);
    s.flow_negative_m3[i] = 0.6 * u(rng);
    full += std::max(s.flow_positive_m3[i] * s.qdot_max[i], -s.flow_negative_m3[i] * s.qdot_min[i]);
  }
  s.max_flow_m3_s = (0.1 + 0.9 * u(rng)) * full;
  return s;
}

// The vertices of {qdot: box, every sign pattern's flow row <= Q} by brute force: every choice
// of n constraints that meet in one feasible point.
std::vector<JointVector> brute_force_vertices(const JointVelocitySet& s) {
  const int n = static_cast<int>(s.qdot_min.size());
  std::vector<Eigen::VectorXd> rows;
  std::vector<double> rhs;
  for (int i = 0; i < n; ++i) {
    rows.push_back(Eigen::VectorXd::Unit(n, i));
    rhs.push_back(s.qdot_max[i]);
    rows.push_back(-Eigen::VectorXd::Unit(n, i));
    rhs.push_back(-s.qdot_min[i]);
  }
  for (int pattern = 0; pattern < (1 << n); ++pattern) {
    Eigen::VectorXd r(n);
    for (int i = 0; i < n; ++i) {
      r[i] = (pattern >> i) & 1 ? s.flow_positive_m3[i] : -s.flow_negative_m3[i];
    }
    rows.push_back(r);
    rhs.push_back(s.max_flow_m3_s);
  }
  const int total = static_cast<int>(rows.size());
  std::vector<JointVector> out;
  std::vector<int> pick(n);
  std::function<void(int, int)> choose = [&](int from, int depth) {
    if (depth == n) {
      Eigen::MatrixXd a(n, n);
      Eigen::VectorXd b(n);
      for (int k = 0; k < n; ++k) {
        a.row(k) = rows[pick[k]].transpose();
        b[k] = rhs[pick[k]];
      }
      Eigen::FullPivLU<Eigen::MatrixXd> lu(a);
      if (lu.rank() < n) return;
      const JointVector x = lu.solve(b);
      for (int k = 0; k < total; ++k) {
        if (rows[k].dot(x) > rhs[k] + 1e-9 * (1.0 + std::abs(rhs[k]))) return;
      }
      for (const auto& y : out) {
        if ((y - x).norm() < 1e-9) return;
      }
      out.push_back(x);
      return;
    }
    for (int i = from; i < total; ++i) {
      pick[depth] = i;
      choose(i + 1, depth + 1);
    }
  };
  choose(0, 0);
  return out;
}

// A random admissible joint velocity: uniform in the box, kept when inside; with probability
// one half pushed out to the boundary of the set along its direction.
JointVector random_admissible(const JointVelocitySet& s, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = static_cast<int>(s.qdot_min.size());
  for (;;) {
    JointVector q(n);
    for (int i = 0; i < n; ++i) q[i] = s.qdot_min[i] + u(rng) * (s.qdot_max[i] - s.qdot_min[i]);
    const double usage = dynamics::limit_usage(s, q);
    if (usage > 1.0) continue;
    if (u(rng) < 0.5 && usage > 0.0) q /= usage;
    return q;
  }
}

}  // namespace

TEST(FlowPolytope, FlowWeightsUseTheAreaOfEachDirection) {
  // Piston area extending, rod side retracting, A_A - A_B extending the differential extension;
  // the tilt's arm is negative, so its positive joint rate retracts the cylinder.
  const auto m = k70m();
  const Pose p = pose_of(m, config::default_crane_config().simulation.q_initial);
  ASSERT_LT(p.arms[2], 0.0);
  const auto& c = m.cylinders;
  EXPECT_DOUBLE_EQ(p.set.flow_positive_m3[1], p.arms[1] * c[1].area_a_m2);
  EXPECT_DOUBLE_EQ(p.set.flow_negative_m3[1], p.arms[1] * c[1].area_b_m2);
  EXPECT_DOUBLE_EQ(p.set.flow_positive_m3[2], -p.arms[2] * c[2].area_b_m2);
  EXPECT_DOUBLE_EQ(p.set.flow_negative_m3[2], -p.arms[2] * c[2].area_a_m2);
  EXPECT_DOUBLE_EQ(p.set.flow_positive_m3[3], 0.5 * (c[3].area_a_m2 - c[3].area_b_m2));
  EXPECT_DOUBLE_EQ(p.set.flow_negative_m3[3], 0.5 * c[3].area_b_m2);
  for (int i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(p.set.qdot_max[i], c[i].v_max_m_s / std::abs(p.arms[i]));
    EXPECT_DOUBLE_EQ(p.set.qdot_min[i], -p.set.qdot_max[i]);
  }
  EXPECT_DOUBLE_EQ(p.set.max_flow_m3_s, m.pump.max_flow_m3_s);
  // Reserves, and a joint at each end.
  JointVector q = p.q;
  q[1] = m.joints[1].q_max;
  q[3] = m.joints[3].q_min;
  const Pose r = pose_of(m, q, {.flow_reserve = 0.05, .cylinder_speed_reserve = 0.1});
  EXPECT_DOUBLE_EQ(r.set.max_flow_m3_s, 0.95 * m.pump.max_flow_m3_s);
  EXPECT_DOUBLE_EQ(r.set.qdot_max[0], 0.9 * c[0].v_max_m_s / std::abs(r.arms[0]));
  EXPECT_EQ(r.set.qdot_max[1], 0.0);
  EXPECT_LT(r.set.qdot_min[1], 0.0);
  EXPECT_EQ(r.set.qdot_min[3], 0.0);
  EXPECT_GT(r.set.qdot_max[3], 0.0);
}

TEST(FlowPolytope, VerticesEqualBruteForceEnumeration) {
  // Random sets (zero bounds, flow limits from a tenth to all of the full-speed demand) and the
  // K70M's at random poses and pump sizes: the same vertices, each once.
  std::mt19937 rng(1);
  for (int trial = 0; trial < 80; ++trial) {
    JointVelocitySet s;
    if (trial % 2 == 0) {
      s = random_set(trial % 4 == 0 ? 3 : 4, rng);
    } else {
      const auto m = k70m(60.0 + 5.0 * trial);
      s = pose_of(m, random_pose(m, rng, 0.3)).set;
    }
    const int n = static_cast<int>(s.qdot_min.size());
    Eigen::MatrixXd v(n, dynamics::max_joint_vertices(n));
    const int count = dynamics::joint_velocity_vertices(s, v);
    const auto brute = brute_force_vertices(s);
    ASSERT_EQ(count, static_cast<int>(brute.size())) << trial;
    for (const auto& b : brute) {
      double nearest = 1e300;
      for (int k = 0; k < count; ++k) nearest = std::min(nearest, (v.col(k) - b).norm());
      EXPECT_LT(nearest, 1e-9 * (1.0 + b.norm())) << trial << ": " << b.transpose();
    }
  }
}

// The support of the joint-velocity set in direction c, max c.qdot over it, independently: a
// fractional knapsack. Each joint moves in the sign of c_i (up to its bound on that side) and
// costs w_i(sign c_i) flow per unit; the flow goes to the best value per flow first.
double support_by_knapsack(const JointVelocitySet& s, const JointVector& c) {
  const int n = static_cast<int>(c.size());
  std::vector<std::pair<double, int>> order;  // value per unit flow, joint
  double value = 0.0, flow_left = s.max_flow_m3_s;
  for (int i = 0; i < n; ++i) {
    const double bound = c[i] > 0 ? s.qdot_max[i] : -s.qdot_min[i];
    const double w = c[i] > 0 ? s.flow_positive_m3[i] : s.flow_negative_m3[i];
    if (c[i] == 0.0 || bound == 0.0) continue;
    if (w == 0.0) {
      value += std::abs(c[i]) * bound;  // free of flow
    } else {
      order.emplace_back(std::abs(c[i]) / w, i);
    }
  }
  std::sort(order.rbegin(), order.rend());
  for (const auto& [ratio, i] : order) {
    const double bound = c[i] > 0 ? s.qdot_max[i] : -s.qdot_min[i];
    const double w = c[i] > 0 ? s.flow_positive_m3[i] : s.flow_negative_m3[i];
    const double rate = std::min(bound, flow_left / w);
    value += std::abs(c[i]) * rate;
    flow_left -= w * rate;
  }
  return value;
}

TEST(FlowPolytope, SupportInEverySignOrthant) {
  // In each of the 16 sign orthants of the K70M's joint rates (each with its own piston or rod
  // areas), the vertex set reaches the set's support for random weights, and the tip hull's
  // vertices reach the tip polytope's support h(d) = h_set(J^T d) in every direction.
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> magnitude(0.05, 1.0);
  FlowPolytope poly(4, 3);
  for (const double pump_lpm : {0.0, 200.0, 120.0, 40.0}) {
    const auto m = k70m(pump_lpm);
    const Pose p = pose_of(m, random_pose(m, rng, 0.0, 0.1));
    poly.update(p.set, p.jacobian);
    poly.build_hull();
    for (int orthant = 0; orthant < 16; ++orthant) {
      for (int k = 0; k < 20; ++k) {
        JointVector c(4);
        for (int i = 0; i < 4; ++i) c[i] = ((orthant >> i) & 1 ? 1.0 : -1.0) * magnitude(rng);
        double best = -1e300;
        for (int v = 0; v < poly.point_count(); ++v) {
          best = std::max(best, c.dot(JointVector(poly.joint_vertex(v))));
        }
        const double expected = support_by_knapsack(p.set, c);
        EXPECT_NEAR(best, expected, 1e-12 * expected) << pump_lpm << " orthant " << orthant;
      }
    }
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector3d d = random_direction(rng);
      double best = -1e300;
      for (const int v : poly.hull_vertices()) best = std::max(best, d.dot(poly.task_points()[v]));
      const double expected = support_by_knapsack(p.set, p.jacobian.transpose() * d);
      EXPECT_NEAR(best, expected, 1e-9 * expected) << pump_lpm;
    }
  }
}

TEST(FlowPolytope, SampledAdmissibleJointVelocitiesLieInsideTheHull) {
  std::mt19937 rng(2);
  FlowPolytope poly(4, 3);
  for (int trial = 0; trial < 40; ++trial) {
    const auto m = k70m(trial % 2 ? 120.0 : 0.0);
    const Pose p = pose_of(m, random_pose(m, rng, 0.2));
    poly.update(p.set, p.jacobian);
    poly.build_hull();
    ASSERT_EQ(poly.dimension(), 3) << trial;
    EXPECT_EQ(poly.hull3().skipped_points(), 0);
    const double tol = 2.0 * poly.hull3().tolerance();
    for (int k = 0; k < 2000; ++k) {
      const JointVector qdot = random_admissible(p.set, rng);
      const Eigen::Vector3d x = p.jacobian * qdot;
      ASSERT_LE(poly.hull3().outside_distance(x), tol) << trial << " qdot " << qdot.transpose();
    }
    // Each hull vertex is the image of an admissible joint velocity on the set's boundary.
    for (const int v : poly.hull_vertices()) {
      const JointVector qdot = poly.joint_vertex(v);
      EXPECT_LE(dynamics::limit_usage(p.set, qdot), 1.0 + 1e-12);
      EXPECT_GE(dynamics::limit_usage(p.set, qdot), 1.0 - 1e-12);
      EXPECT_LT((p.jacobian * qdot - poly.task_points()[v]).norm(), 1e-12);
    }
  }
}

TEST(FlowPolytope, LpEqualsTheHullAlongEveryDirection) {
  // Two independent answers to "how far along u": the LP over joint velocities and the hull's
  // faces.
  std::mt19937 rng(3);
  FlowPolytope poly(4, 3);
  double worst = 0.0;
  for (int trial = 0; trial < 60; ++trial) {
    const auto m = k70m(trial % 3 == 0 ? 0.0 : 80.0 + 4.0 * trial);
    const Pose p = pose_of(m, random_pose(m, rng, 0.2));
    poly.update(p.set, p.jacobian);
    poly.build_hull();
    for (int k = 0; k < 50; ++k) {
      const Eigen::Vector3d u = random_direction(rng);
      const double lp = poly.max_speed(u);
      ASSERT_EQ(poly.lp_status(), dynamics::LpStatus::kOptimal);
      const double ray = poly.hull3().ray_length(u);
      EXPECT_NEAR(lp, ray, 1e-8 * std::max(ray, 1e-3)) << trial << " u " << u.transpose();
      worst = std::max(worst, std::abs(lp - ray) / std::max(ray, 1e-3));
      // Its joint velocity is admissible and moves the tip at that speed along u.
      const JointVector& qdot = poly.max_speed_joint_velocity();
      EXPECT_LE(dynamics::limit_usage(p.set, qdot), 1.0 + 1e-9);
      EXPECT_LT((p.jacobian * qdot - lp * u).norm(), 1e-9 * std::max(lp, 1e-3));
    }
  }
  std::printf(
      "[ figures  ] LP against the hull's faces, 3000 directions: largest relative "
      "difference %.1e\n",
      worst);
}

TEST(FlowPolytope, DenseNullSpaceSamplingApproachesTheLpFromBelow) {
  // For the K70M every joint velocity moving the tip along u is s (p + t n) (the product's own
  // solution line, null_space_resolution.hpp); for each t the set allows s up to
  // speed_along(p + t n). Sampling t densely must approach the LP's optimum, never exceed it.
  std::mt19937 rng(4);
  FlowPolytope poly(4, 3);
  double closest = 0.0;  // the largest shortfall of the sampling below the LP, relative
  int sampled = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const auto m = k70m(trial % 2 ? 120.0 : 0.0);
    const Pose p = pose_of(m, random_pose(m, rng, 0.1));
    const Eigen::Vector3d u = random_direction(rng);
    dynamics::SolutionLine line;
    if (!dynamics::solution_line(p.jacobian, u, line)) continue;
    poly.update(p.set, p.jacobian);
    const double lp = poly.max_speed(u);
    double best = 0.0, best_t = 0.0;
    for (double t = -20.0; t <= 20.0; t += 1e-3) {
      const double s = dynamics::speed_along(p.set, line.p + t * line.n);
      if (s > best) {
        best = s;
        best_t = t;
      }
    }
    for (double h = 1e-3; h > 1e-9; h *= 0.5) {  // refine around the best sample
      for (const double t : {best_t - h, best_t + h}) {
        const double s = dynamics::speed_along(p.set, line.p + t * line.n);
        if (s > best) {
          best = s;
          best_t = t;
        }
      }
    }
    EXPECT_LE(best, lp * (1.0 + 1e-9)) << trial;
    EXPECT_GE(best, lp * (1.0 - 1e-6)) << trial;
    closest = std::max(closest, 1.0 - best / lp);
    ++sampled;
  }
  std::printf(
      "[ figures  ] %d poses: dense sampling of the null space within %.1e of the LP, "
      "never above it\n",
      sampled, closest);
}

TEST(FlowPolytope, VolumeAgreesWithMonteCarlo) {
  // Uniform points in the hull's bounding box, inside when the LP reaches them: x is in J P
  // exactly when |x| <= max_speed(x / |x|) (the set contains the origin and is convex).
  std::mt19937 rng(5);
  FlowPolytope poly(4, 3);
  for (int trial = 0; trial < 4; ++trial) {
    const auto m = k70m(trial % 2 ? 120.0 : 0.0);
    const Pose p = pose_of(m, random_pose(m, rng, 0.0, 0.1));
    poly.update(p.set, p.jacobian);
    poly.build_hull();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (const int v : poly.hull_vertices()) {
      lo = lo.cwiseMin(poly.task_points()[v]);
      hi = hi.cwiseMax(poly.task_points()[v]);
    }
    const double box = (hi - lo).prod();
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const int samples = 20000;
    int inside = 0;
    for (int k = 0; k < samples; ++k) {
      const Eigen::Vector3d x =
          lo + Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).cwiseProduct(hi - lo);
      if (x.norm() <= poly.max_speed(x)) ++inside;
    }
    const double f = static_cast<double>(inside) / samples;
    const double estimate = f * box, sigma = box * std::sqrt(f * (1.0 - f) / samples);
    EXPECT_NEAR(poly.volume(), estimate, 4.0 * sigma)
        << trial << ": volume " << poly.volume() << " m^3/s^3, Monte Carlo " << estimate;
    std::printf("[ figures  ] volume %.3f m^3/s^3, Monte Carlo %.3f +- %.3f (%d samples)\n",
                poly.volume(), estimate, sigma, samples);
    EXPECT_GT(poly.volume(), 0.0);
  }
}

TEST(FlowPolytope, SpeedAlongTheResolutionIsTheScalingStagesBound) {
  // What the controller's scaling stage allows along its own resolution of u (full scaling:
  // path_speed_limits with the reserve on flow and cylinder speeds) is the polytope's speed
  // along that joint direction, to rounding; and the best over all joint velocities (the LP) is
  // never below it. Random poses (a fifth of the joints at an end), directions and intended
  // speeds, every resolution, the K70M's pump and a smaller one.
  std::mt19937 rng(6);
  const auto cfg = config::default_crane_config();
  const double reserve = cfg.control.flow_reserve;
  FlowPolytope poly(4, 3);
  int compared = 0, at_ends = 0, flow_bound = 0, into_ends = 0;
  double worst = 0.0, gain = 0.0;
  std::uniform_real_distribution<double> speed(0.05, 2.0);
  for (int trial = 0; trial < 4000; ++trial) {
    const auto m = k70m(trial % 2 ? 120.0 : 0.0);
    scaling::TipPathConfig pc;
    pc.flow_reserve = reserve;
    pc.resolution = dynamics::kResolutions[trial % dynamics::kResolutions.size()];
    scaling::TipPath path(m, pc);
    const JointVector q = random_pose(m, rng, 0.2);
    const Eigen::Vector3d u = random_direction(rng);
    scaling::TipPathInput in;
    in.direction = u;
    in.intended_speed = speed(rng);
    scaling::TipPathOutput out;
    path.update(q, in, out);
    const Pose p = pose_of(m, q, {.flow_reserve = reserve, .cylinder_speed_reserve = reserve});
    // Only where the resolution moves the tip along u (not at a corner of the workspace).
    if ((p.jacobian * out.geometry.f1 - u).norm() > 1e-9) continue;
    scaling::SpeedLimits limits;
    scaling::path_speed_limits(m, out.geometry, reserve, limits);
    const double product = std::min(limits.sdot_flow, limits.sdot_cylinder);
    const double polytope = dynamics::speed_along(p.set, out.geometry.f1);
    // Where u cannot be done without driving a joint into the end it is at (the slew at its
    // stop and u sideways), the polytope allows nothing along f' (a joint within 1e-4 of its end
    // counts as at it), and the controller almost nothing: its end damping allows at most the
    // speed that stops in the remaining 1e-4, a few cm/s of path speed (0.026 m/s measured).
    bool into_end = false;
    for (int i = 0; i < 4; ++i) {
      const double f = out.geometry.f1[i];
      into_end = into_end || (p.set.qdot_max[i] == 0.0 && f > 1e-12) ||
                 (p.set.qdot_min[i] == 0.0 && f < -1e-12);
    }
    if (into_end) {
      EXPECT_EQ(polytope, 0.0) << trial;
      EXPECT_LE(out.sdot_joint_limit, 0.05) << trial;
      ++into_ends;
      continue;
    }
    ASSERT_NEAR(polytope, product, 1e-9 * product)
        << trial << " q " << q.transpose() << " u " << u.transpose();
    worst = std::max(worst, std::abs(polytope - product) / product);
    poly.update(p.set, p.jacobian);
    const double lp = poly.max_speed(u);
    EXPECT_GE(lp, product * (1.0 - 1e-9)) << trial;
    gain += lp / product;
    ++compared;
    at_ends += (p.set.qdot_max.array() == 0.0).any() || (p.set.qdot_min.array() == 0.0).any();
    flow_bound += limits.sdot_flow < limits.sdot_cylinder;
  }
  EXPECT_GT(compared, 3000);
  EXPECT_GT(at_ends, 1000);    // joints at an end were among them
  EXPECT_GT(flow_bound, 500);  // and the pump's flow set the bound in many
  std::printf(
      "[ figures  ] %d poses compared (%d with a joint at an end, %d flow-bound): largest "
      "relative difference %.1e; LP over the scaling's bound %.3f on average; %d driven into an "
      "end, held at 0 by both\n",
      compared, at_ends, flow_bound, worst, gain / compared, into_ends);
}

TEST(FlowPolytope, SpeedAlongTheSnsIsTheFlowOnlyPrescalingBound) {
  // The flow-only mode (ControllerOptions kFlowOnly): the SNS resolves the command within the
  // joints' position bounds, flow_prescale scales it with the reserve on the flow only.
  std::mt19937 rng(7);
  const double reserve = 0.05;
  int compared = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const auto m = k70m(trial % 2 ? 120.0 : 0.0);
    const JointVector q = random_pose(m, rng, 0.0, 0.01);
    const Pose p = pose_of(m, q, {.flow_reserve = reserve});
    const Eigen::Vector3d v = 10.0 * random_direction(rng);  // beyond what any pose gives
    JointVector qddot_max(4);
    for (int i = 0; i < 4; ++i) qddot_max[i] = m.cylinders[i].a_max_m_s2 / std::abs(p.arms[i]);
    dynamics::JointRateBounds bounds;
    dynamics::joint_rate_bounds(m, q, JointVector::Constant(4, 1e3), qddot_max, 0.01, bounds);
    dynamics::SnsResult sns;
    dynamics::sns_velocity_ik(p.jacobian, v, bounds, sns);
    scaling::FlowPrescalingResult pre;
    scaling::flow_prescale(m, p.arms, sns.qdot, reserve, pre);
    if (!(pre.scale < 1.0)) continue;
    EXPECT_NEAR(dynamics::speed_along(p.set, sns.qdot), pre.scale, 1e-9 * pre.scale) << trial;
    ++compared;
  }
  EXPECT_GT(compared, 1900);
}

TEST(FlowPolytope, ResolutionShapedBeyondTheHydraulicsReachesTheLp) {
  // Asked for more than the hydraulics give, the tip path's resolution picks the joint motion
  // that lets the path run fastest (null_space_resolution.hpp, step 4): the LP's optimum, when
  // nothing else constrains the null space. Here the stopping distance before an end is made
  // negligible (a stop needs only a few millimetres) and the end avoidance is off, so the
  // position bounds do not interfere. Below the hydraulics' limit the resolution's own cost
  // decides, and the speed along it is at most the LP's.
  std::mt19937 rng(8);
  FlowPolytope poly(4, 3);
  int compared = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const auto m = k70m(trial % 2 ? 120.0 : 0.0);
    scaling::TipPathConfig pc;
    pc.resolution = dynamics::kResolutions[trial % dynamics::kResolutions.size()];
    pc.deceleration_max = 1e3;
    pc.jerk_max = 1e5;
    pc.end_weight = 0.0;
    scaling::TipPath path(m, pc);
    const JointVector q = random_pose(m, rng, 0.0, 0.25);
    const Eigen::Vector3d u = random_direction(rng);
    const Pose p = pose_of(m, q);
    poly.update(p.set, p.jacobian);
    const double lp = poly.max_speed(u);
    for (const double share : {0.5, 1.01, 2.0}) {
      path.reset();
      scaling::TipPathInput in;
      in.direction = u;
      in.intended_speed = share * lp;
      scaling::TipPathOutput out;
      path.update(q, in, out);
      ASSERT_LT((p.jacobian * out.geometry.f1 - u).norm(), 1e-9);
      const double along = dynamics::speed_along(p.set, out.geometry.f1);
      EXPECT_LE(along, lp * (1.0 + 1e-9)) << trial;
      if (share > 1.0) {
        EXPECT_GE(along, lp * (1.0 - 1e-6)) << trial << " " << dynamics::to_string(pc.resolution);
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 600);
}

TEST(FlowPolytope, JointsAtTheirEnds) {
  // Every joint at an end, each way round: the set keeps only motion away from the ends, every
  // vertex and the LP's joint velocity respect it, and the hull still contains the origin (on
  // its boundary: towards the ends the crane cannot move at all).
  const auto m = k70m(120.0);
  FlowPolytope poly(4, 3);
  for (int corner = 0; corner < 16; ++corner) {
    JointVector q(4);
    for (int i = 0; i < 4; ++i) {
      q[i] = (corner >> i) & 1 ? m.joints[i].q_max : m.joints[i].q_min;
    }
    q[0] = 0.3;  // the slew's ends are half a turn either way: leave it free
    const Pose p = pose_of(m, q);
    poly.update(p.set, p.jacobian);
    poly.build_hull();
    for (int k = 0; k < poly.point_count(); ++k) {
      const JointVector v = poly.joint_vertex(k);
      for (int i = 1; i < 4; ++i) {
        if ((corner >> i) & 1) {
          EXPECT_LE(v[i], 0.0);
        } else {
          EXPECT_GE(v[i], 0.0);
        }
      }
    }
    EXPECT_FALSE(std::isnan(poly.volume()));
    EXPECT_GE(poly.volume(), 0.0);
    EXPECT_LE(poly.hull3().outside_distance(Eigen::Vector3d::Zero()), 2 * poly.hull3().tolerance());
    std::mt19937 rng(corner);
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector3d u = random_direction(rng);
      const double lp = poly.max_speed(u);
      EXPECT_GE(lp, 0.0);
      EXPECT_LE(dynamics::limit_usage(p.set, poly.max_speed_joint_velocity()), 1.0 + 1e-9);
      if (poly.dimension() == 3) {
        EXPECT_NEAR(lp, poly.hull3().ray_length(u), 1e-8 * std::max(lp, 1e-3));
      }
    }
  }
}

TEST(FlowPolytope, SingularJacobianHasNoVolumeAndNoNan) {
  // A rank-2 task (the third row a mix of the other two): a flat polytope of finite area; the
  // LP gives a speed along the plane (the flat hull's) and 0 across it. A zero task: nothing.
  std::mt19937 rng(9);
  const auto m = k70m(120.0);
  FlowPolytope poly(4, 3);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose p = pose_of(m, random_pose(m, rng, 0.0, 0.1));
    TaskJacobian j = p.jacobian;
    j.row(2) = 0.3 * j.row(0) - 0.7 * j.row(1);
    poly.update(p.set, j);
    poly.build_hull();
    EXPECT_EQ(poly.dimension(), 2);
    EXPECT_EQ(poly.volume(), 0.0);
    EXPECT_TRUE(std::isfinite(poly.area()));
    EXPECT_GT(poly.area(), 0.0);
    const Eigen::Vector3d normal = Eigen::Vector3d(0.3, -0.7, -1.0).normalized();
    const Eigen::Vector3d in_plane = normal.unitOrthogonal();
    const double lp = poly.max_speed(in_plane);
    EXPECT_GT(lp, 0.0);
    EXPECT_NEAR(lp, poly.hull3().ray_length(in_plane), 1e-8 * lp);
    EXPECT_EQ(poly.max_speed(normal), 0.0);
  }
  poly.update(pose_of(m, random_pose(m, rng)).set, TaskJacobian::Zero(3, 4));
  poly.build_hull();
  EXPECT_EQ(poly.dimension(), 0);
  EXPECT_EQ(poly.volume(), 0.0);
  EXPECT_EQ(poly.area(), 0.0);
  EXPECT_EQ(poly.max_speed(Eigen::Vector3d::UnitX()), 0.0);
  EXPECT_EQ(poly.max_speed(Eigen::Vector3d::Zero()), 0.0);
}

TEST(FlowPolytope, PlanarArmInItsPlane) {
  // The planar 2R arm: its plane is the crane frame's x-y; the 2-D polytope's area against Monte
  // Carlo, its LP against the polygon; in 3-D its polytope is flat. Stretched out (elbow 0) the
  // arm is singular: a segment, area 0.
  const auto m = planar_2r();
  const auto basis = dynamics::planar_task_basis(m);
  ASSERT_TRUE(basis.has_value());
  EXPECT_EQ(basis->row(0), Eigen::RowVector3d(1, 0, 0));
  EXPECT_EQ(basis->row(1), Eigen::RowVector3d(0, 1, 0));
  EXPECT_FALSE(dynamics::planar_task_basis(k70m()).has_value());
  std::mt19937 rng(10);
  FlowPolytope plane(2, 2), space(2, 3);
  for (int trial = 0; trial < 10; ++trial) {
    const Pose p = pose_of(m, random_pose(m, rng, 0.0, 0.1));
    const dynamics::TaskMatrix j2 = *basis * p.jacobian;
    plane.update(p.set, j2);
    plane.build_hull();
    ASSERT_EQ(plane.dimension(), 2);
    space.update(p.set, p.jacobian);
    space.build_hull();
    EXPECT_EQ(space.dimension(), 2);
    EXPECT_NEAR(space.area(), plane.area(), 1e-9 * plane.area());
    Eigen::Vector2d lo(1e300, 1e300), hi = -lo;
    for (const int v : plane.hull_vertices()) {
      lo = lo.cwiseMin(plane.task_points()[v].head<2>());
      hi = hi.cwiseMax(plane.task_points()[v].head<2>());
    }
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int inside = 0;
    const int samples = 20000;
    for (int k = 0; k < samples; ++k) {
      const Eigen::Vector2d x = lo + Eigen::Vector2d(unit(rng), unit(rng)).cwiseProduct(hi - lo);
      if (x.norm() <= plane.max_speed(x)) ++inside;
    }
    const double f = static_cast<double>(inside) / samples, box = (hi - lo).prod();
    EXPECT_NEAR(plane.area(), f * box, 4.0 * box * std::sqrt(f * (1 - f) / samples)) << trial;
    for (int k = 0; k < 20; ++k) {
      const double a = 2 * std::numbers::pi * unit(rng);
      const Eigen::Vector2d u(std::cos(a), std::sin(a));
      const double lp = plane.max_speed(u);
      EXPECT_NEAR(lp, plane.hull2().ray_length(u), 1e-8 * lp);
      const Eigen::Vector3d u3(u.x(), u.y(), 0.0);
      EXPECT_NEAR(space.max_speed(u3), lp, 1e-8 * lp);
    }
  }
  JointVector straight =
      config::load_crane_config(CRANEASSIST_SOURCE_DIR "/config/cranes/planar_2r.yaml")
          .simulation.q_initial;
  straight[1] = 0.0;
  const Pose p = pose_of(m, straight);
  plane.update(p.set, *basis * p.jacobian);
  plane.build_hull();
  EXPECT_EQ(plane.dimension(), 1);
  EXPECT_EQ(plane.area(), 0.0);
  EXPECT_EQ(plane.max_speed(Eigen::Vector2d(std::cos(straight[0]), std::sin(straight[0]))), 0.0);
}

TEST(FlowPolytope, UpdateHullAndLpAllocateNothing) {
  const auto m = k70m(120.0);
  FlowPolytope poly(4, 3);
  std::mt19937 rng(11);
  std::vector<Pose> poses;
  for (int k = 0; k < 20; ++k) poses.push_back(pose_of(m, random_pose(m, rng, 0.2)));
  std::vector<Eigen::Vector3d> directions;
  for (int k = 0; k < 20; ++k) directions.push_back(random_direction(rng));
  double sink = 0.0;
  const long before = test::heap_allocations();
  for (int k = 0; k < 20; ++k) {
    poly.update(poses[k].set, poses[k].jacobian);
    poly.build_hull();
    sink += poly.volume() + poly.max_speed(directions[k]);
  }
  EXPECT_EQ(test::heap_allocations(), before);
  EXPECT_GT(sink, 0.0);
}
