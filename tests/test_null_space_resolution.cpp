// The exact resolution on the solution line (dynamics/null_space_resolution.hpp): every solution
// meets the task, each priority level holds whenever it can, a fallback is the best a fine sweep
// of the null coordinate finds, and without bounds it is the plain optimum of each resolution
// (checked against the paper's extension-rate parameterisation, resolutions.hpp).
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "allocation_counter.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/null_space_resolution.hpp"
#include "craneassist/dynamics/resolutions.hpp"

using namespace craneassist::dynamics;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

const CraneModel& k70m() {
  static const CraneModel model = craneassist::config::default_crane_config().model;
  return model;
}

struct Case {
  JointVector q;
  TaskJacobian jacobian;
  Eigen::Vector3d u;
  JointVector arms, force;
  SolutionLine line;
};

Case random_case(std::mt19937& rng) {
  const auto& m = k70m();
  Case c;
  c.q.resize(4);
  for (int i = 0; i < 4; ++i) {
    std::uniform_real_distribution<double> d(m.joints[i].q_min + 0.05, m.joints[i].q_max - 0.05);
    c.q[i] = d(rng);
  }
  KinematicsData kin;
  tip_jacobian(m, kin, c.q, c.jacobian);
  std::normal_distribution<double> nd(0.0, 1.0);
  c.u = Eigen::Vector3d(nd(rng), nd(rng), nd(rng)).normalized();
  cylinder_arms(m, c.q, c.arms);
  std::normal_distribution<double> force(0.0, 5e4);
  c.force.resize(4);
  for (int i = 0; i < 4; ++i) c.force[i] = force(rng);
  return c;
}

JointRateBounds unbounded() {
  return {JointVector::Constant(4, -kInf), JointVector::Constant(4, kInf)};
}

NullSpaceProblem problem_for(const Case& c) {
  NullSpaceProblem p;
  p.line = &c.line;
  p.dc_dq = &c.arms;
  p.cylinder_force = &c.force;
  p.position = unbounded();
  p.hydraulic = unbounded();
  return p;
}

constexpr Resolution kAll[] = {Resolution::kPinvJoint, Resolution::kPinvActuator,
                               Resolution::kMinFlow, Resolution::kMinLsPower};

// The cost of each resolution along a fine sweep of tau over [lo, hi], its minimum.
double swept_minimum(Resolution r, const Case& c, double lo, double hi) {
  double best = kInf;
  for (int k = 0; k <= 20000; ++k) {
    const double tau = lo + (hi - lo) * k / 20000.0;
    const JointVector f = c.line.p + tau * c.line.n;
    best = std::min(best, resolution_cost(k70m(), r, f, c.arms, &c.force));
  }
  return best;
}

}  // namespace

TEST(SolutionLine, EverySolutionOnTheLineMeetsTheTask) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 200; ++trial) {
    Case c = random_case(rng);
    ASSERT_TRUE(solution_line(c.jacobian, c.u, c.line));
    EXPECT_NEAR(c.line.n.norm(), 1.0, 1e-12);
    EXPECT_LT((c.jacobian * c.line.n).norm(), 1e-9 * c.jacobian.norm());
    EXPECT_LT(std::abs(c.line.p.dot(c.line.n)), 1e-9 * (1.0 + c.line.p.norm()));
    for (double tau : {-3.0, 0.0, 0.7, 12.0}) {
      const JointVector f = c.line.p + tau * c.line.n;
      EXPECT_LT((c.jacobian * f - c.u).norm(), 1e-9 * (1.0 + f.norm()));
    }
    EXPECT_GT(c.line.conditioning, 0.0);
    EXPECT_LE(c.line.conditioning, 1.0);
  }
}

TEST(SolutionLine, RankDeficientJacobianIsRefused) {
  TaskJacobian j(3, 4);
  j << 1, 0, 0, 1,  //
      0, 1, 0, 0,   //
      0, 0, 0, 0;   // nothing moves along z
  SolutionLine line;
  EXPECT_FALSE(solution_line(j, Eigen::Vector3d(0, 0, 1), line));
  TaskJacobian three(3, 3);
  three.setIdentity();
  EXPECT_FALSE(solution_line(three, Eigen::Vector3d(1, 0, 0), line));
}

TEST(NullSpaceResolution, WithoutBoundsEachResolutionIsItsOptimum) {
  std::mt19937 rng(2);
  int compared = 0;
  for (int trial = 0; trial < 100; ++trial) {
    Case c = random_case(rng);
    ASSERT_TRUE(solution_line(c.jacobian, c.u, c.line));
    // A finite hydraulic box keeps the problem bounded (as the controller's always is).
    NullSpaceProblem p = problem_for(c);
    p.hydraulic = {JointVector::Constant(4, -20.0), JointVector::Constant(4, 20.0)};
    for (Resolution r : kAll) {
      NullSpaceResult out;
      resolve_null_space(k70m(), r, p, out);
      ASSERT_EQ(out.status, NullSpaceStatus::kOptimal);
      EXPECT_LT((c.jacobian * out.f - c.u).norm(), 1e-9 * (1.0 + out.f.norm()));
      const double sweep = swept_minimum(r, c, out.hard_lo, out.hard_hi);
      EXPECT_LE(out.cost, sweep * (1 + 1e-6) + 1e-12) << to_string(r) << " trial " << trial;
    }
    // The same optimum as the paper's extension-rate parameterisation where that one is
    // defined (the two parameterise the same line).
    if (std::abs(Eigen::Matrix3d(c.jacobian.leftCols<3>()).determinant()) < 1e-2) continue;
    ExtensionResolutionInput in;
    in.jacobian = &c.jacobian;
    in.v_tip = c.u;
    in.dc_dq = &c.arms;
    in.cylinder_force = &c.force;
    const JointRateBounds loose{JointVector::Constant(4, -20.0), JointVector::Constant(4, 20.0)};
    in.bounds = &loose;
    for (Resolution r :
         {Resolution::kPinvActuator, Resolution::kMinFlow, Resolution::kMinLsPower}) {
      ExtensionResolutionResult ext;
      resolve_by_extension(k70m(), r, in, ext);
      NullSpaceResult out;
      resolve_null_space(k70m(), r, p, out);
      if (!ext.feasible) continue;
      EXPECT_NEAR(out.cost, ext.cost, 1e-7 * (1.0 + std::abs(ext.cost))) << to_string(r);
      ++compared;
    }
    // pinv-joint: the minimum-norm solution itself.
    NullSpaceResult out;
    resolve_null_space(k70m(), Resolution::kPinvJoint, p, out);
    EXPECT_LT((out.f - c.line.p).norm(), 1e-9);
  }
  EXPECT_GT(compared, 100);
}

TEST(NullSpaceResolution, PositionBoundsHoldWheneverTheyCan) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> width(0.05, 2.0);
  int feasible = 0, infeasible = 0;
  for (int trial = 0; trial < 400; ++trial) {
    Case c = random_case(rng);
    ASSERT_TRUE(solution_line(c.jacobian, c.u, c.line));
    NullSpaceProblem p = problem_for(c);
    p.hydraulic = {JointVector::Constant(4, -50.0), JointVector::Constant(4, 50.0)};
    for (int i = 0; i < 4; ++i) {
      p.position.upper[i] = width(rng);
      p.position.lower[i] = -width(rng);
    }
    for (Resolution r : kAll) {
      NullSpaceResult out;
      resolve_null_space(k70m(), r, p, out);
      EXPECT_LT((c.jacobian * out.f - c.u).norm(), 1e-9 * (1.0 + out.f.norm()));
      // Feasible somewhere on the line (a sweep finds it)?
      double best_share = kInf;
      for (int k = 0; k <= 40000; ++k) {
        const double tau = -50.0 + 100.0 * k / 40000.0;
        const JointVector f = c.line.p + tau * c.line.n;
        double share = 0.0;
        for (int i = 0; i < 4; ++i) {
          share =
              std::max(share, f[i] > 0 ? f[i] / p.position.upper[i] : f[i] / p.position.lower[i]);
        }
        best_share = std::min(best_share, share);
      }
      double share = 0.0;
      for (int i = 0; i < 4; ++i) {
        share = std::max(
            share, out.f[i] > 0 ? out.f[i] / p.position.upper[i] : out.f[i] / p.position.lower[i]);
      }
      if (best_share <= 1.0 - 1e-6) {
        ++feasible;
        EXPECT_NE(out.status, NullSpaceStatus::kPositionLimit) << to_string(r);
        EXPECT_LE(share, 1.0 + 1e-9) << to_string(r);
      } else if (best_share > 1.0 + 1e-6) {
        ++infeasible;
        EXPECT_EQ(out.status, NullSpaceStatus::kPositionLimit) << to_string(r);
        // The fallback lets the path run fastest: the smallest share the sweep finds.
        EXPECT_LE(share, best_share * (1 + 1e-4)) << to_string(r);
      }
    }
  }
  EXPECT_GT(feasible, 200);
  EXPECT_GT(infeasible, 50);
}

TEST(NullSpaceResolution, AJointAtItsEndNeverMovesIntoIt) {
  std::mt19937 rng(4);
  int checked = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Case c = random_case(rng);
    ASSERT_TRUE(solution_line(c.jacobian, c.u, c.line));
    NullSpaceProblem p = problem_for(c);
    p.hydraulic = {JointVector::Constant(4, -50.0), JointVector::Constant(4, 50.0)};
    const int at_end = static_cast<int>(rng() % 4);
    const bool upper = rng() % 2 == 0;
    (upper ? p.position.upper : p.position.lower)[at_end] = 0.0;
    // Other joints tight too, so the lower levels want to move it.
    for (int i = 0; i < 4; ++i) {
      if (i == at_end) continue;
      p.position.upper[i] = 0.3;
      p.position.lower[i] = -0.3;
    }
    if (std::abs(c.line.n[at_end]) < 1e-6) continue;  // the null space cannot move it
    for (Resolution r : kAll) {
      NullSpaceResult out;
      resolve_null_space(k70m(), r, p, out);
      const double towards = upper ? out.f[at_end] : -out.f[at_end];
      EXPECT_LE(towards, 1e-9) << to_string(r) << " joint " << at_end;
      ++checked;
    }
  }
  EXPECT_GT(checked, 500);
}

TEST(NullSpaceResolution, HydraulicFallbackMaximisesTheSpeedTheCylindersAllow) {
  std::mt19937 rng(5);
  int fallbacks = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Case c = random_case(rng);
    ASSERT_TRUE(solution_line(c.jacobian, c.u, c.line));
    NullSpaceProblem p = problem_for(c);
    // Cylinder-speed bounds of the K70M at a path speed of 2 m/s: often infeasible.
    for (int i = 0; i < 4; ++i) {
      const double rate = k70m().cylinders[i].v_max_m_s / std::abs(c.arms[i]) / 2.0;
      p.hydraulic.upper[i] = rate;
      p.hydraulic.lower[i] = -rate;
    }
    p.flow_limit_m2 = k70m().pump.max_flow_m3_s / 2.0;
    NullSpaceResult out;
    resolve_null_space(k70m(), Resolution::kMinLsPower, p, out);
    if (out.status != NullSpaceStatus::kHydraulicLimit) continue;
    ++fallbacks;
    auto load = [&](const JointVector& f) {
      double worst = 0.0, flow = 0.0;
      for (int i = 0; i < 4; ++i) {
        worst = std::max(worst, std::abs(f[i]) / p.hydraulic.upper[i]);
        const double v = c.arms[i] * f[i];
        flow += flow_area_m2(k70m().cylinders[i], v) * std::abs(v);
      }
      return std::max(worst, flow / p.flow_limit_m2);
    };
    double best = kInf;
    for (int k = 0; k <= 40000; ++k) {
      const double tau = out.hard_lo + (out.hard_hi - out.hard_lo) * k / 40000.0;
      best = std::min(best, load(c.line.p + tau * c.line.n));
    }
    EXPECT_GT(best, 1.0);
    EXPECT_LE(load(out.f), best * (1 + 1e-4));
  }
  EXPECT_GT(fallbacks, 20);
}

TEST(NullSpaceResolution, EndAvoidanceHandsMotionToTheOtherJoints) {
  std::mt19937 rng(6);
  int reduced = 0, trials = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Case c = random_case(rng);
    ASSERT_TRUE(solution_line(c.jacobian, c.u, c.line));
    NullSpaceProblem p = problem_for(c);
    p.hydraulic = {JointVector::Constant(4, -20.0), JointVector::Constant(4, 20.0)};
    for (Resolution r : kAll) {
      NullSpaceResult plain;
      resolve_null_space(k70m(), r, p, plain);
      // The joint the plain optimum moves fastest (that the null space can move), near its end in
      // that direction.
      int i = 1;
      for (int k = 1; k < 4; ++k) {
        if (std::abs(plain.f[k]) > std::abs(plain.f[i])) i = k;
      }
      if (std::abs(c.line.n[i]) < 0.05 || std::abs(plain.f[i]) < 1e-3) continue;
      NullSpaceProblem avoid = p;
      avoid.avoid_weight = JointVector::Zero(4);
      avoid.avoid_sign = JointVector::Zero(4);
      avoid.avoid_weight[i] = 10.0;
      avoid.avoid_sign[i] = plain.f[i] > 0 ? 1.0 : -1.0;
      NullSpaceResult out;
      resolve_null_space(k70m(), r, avoid, out);
      ++trials;
      EXPECT_LE(std::abs(out.f[i]), std::abs(plain.f[i]) + 1e-12) << to_string(r);
      reduced += std::abs(out.f[i]) < 0.9 * std::abs(plain.f[i]);
      EXPECT_LT((c.jacobian * out.f - c.u).norm(), 1e-9 * (1.0 + out.f.norm()));
    }
  }
  EXPECT_GT(trials, 100);
  EXPECT_GT(reduced, trials / 2);
}

TEST(NullSpaceResolution, HandoverBoundsYieldToTheHardOnes) {
  // Hand-over bounds tighter than anything feasible: the solution stays within the position and
  // hydraulic bounds and says the hand-over bound is exceeded.
  std::mt19937 rng(7);
  int handovers = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Case c = random_case(rng);
    ASSERT_TRUE(solution_line(c.jacobian, c.u, c.line));
    NullSpaceProblem p = problem_for(c);
    p.hydraulic = {JointVector::Constant(4, -20.0), JointVector::Constant(4, 20.0)};
    p.position = {JointVector::Constant(4, -5.0), JointVector::Constant(4, 5.0)};
    p.handover = {JointVector::Constant(4, -1e-3), JointVector::Constant(4, 1e-3)};
    NullSpaceResult out;
    resolve_null_space(k70m(), Resolution::kMinFlow, p, out);
    if (out.status == NullSpaceStatus::kPositionLimit) continue;
    EXPECT_LE(out.f.cwiseAbs().maxCoeff(), 5.0 + 1e-9);
    handovers += out.status == NullSpaceStatus::kHandover;
  }
  EXPECT_GT(handovers, 100);
}

TEST(NullSpaceResolution, ResolvingAllocatesNothing) {
  std::mt19937 rng(8);
  Case c = random_case(rng);
  NullSpaceResult out;
  const long before = craneassist::test::heap_allocations();
  for (int k = 0; k < 50; ++k) {
    ASSERT_TRUE(solution_line(c.jacobian, c.u, c.line));
    NullSpaceProblem p = problem_for(c);
    p.hydraulic = {JointVector::Constant(4, -2.0), JointVector::Constant(4, 2.0)};
    p.flow_limit_m2 = 1e-3;
    p.handover = {JointVector::Constant(4, -0.1), JointVector::Constant(4, 0.1)};
    p.avoid_weight = JointVector::Constant(4, 1.0);
    p.avoid_sign = JointVector::Constant(4, 1.0);
    for (Resolution r : kAll) resolve_null_space(k70m(), r, p, out);
  }
  EXPECT_EQ(craneassist::test::heap_allocations() - before, 0);
}
