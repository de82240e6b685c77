// The exact resolution on the solution line (dynamics/null_space_resolution.hpp): every solution
// meets the task, each priority level holds whenever it can, a fallback is the best a fine sweep
// of the null coordinate finds, and without bounds it is the plain optimum of each resolution
// (checked against the paper's extension-rate parameterisation, resolutions.hpp).
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "allocation_counter.hpp"
#include "craneassist/dynamics/null_space_resolution.hpp"
#include "craneassist/dynamics/resolutions.hpp"
#include "random_tip_task.hpp"

using namespace craneassist::dynamics;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

using craneassist::test::k70m;

// The task's tip velocity as a unit direction u, and the solution line of J f = u.
struct Case : craneassist::test::RandomTipTask {
  Eigen::Vector3d u;
  SolutionLine line;
};

Case random_case(std::mt19937& rng) {
  Case c;
  static_cast<craneassist::test::RandomTipTask&>(c) = craneassist::test::random_tip_task(rng, 1.0);
  c.u = c.v.normalized();
  return c;
}

// Every joint rate within [-bound, bound].
JointRateBounds box(double bound) {
  return {JointVector::Constant(4, -bound), JointVector::Constant(4, bound)};
}

// `trials` random cases drawn from a generator seeded with seed, each with its solution line.
std::vector<Case> cases_on_their_lines(unsigned seed, int trials) {
  std::mt19937 rng(seed);
  std::vector<Case> out;
  for (int trial = 0; trial < trials; ++trial) {
    out.push_back(random_case(rng));
    EXPECT_TRUE(solution_line(out.back().jacobian, out.back().u, out.back().line)) << trial;
  }
  return out;
}

JointRateBounds unbounded() {
  return box(kInf);
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

// The smallest value of measure(f) over the solutions f = p + tau n of a fine sweep of tau over
// [lo, hi] in `steps` steps.
template <class Measure>
double swept_minimum(const Case& c, double lo, double hi, int steps, Measure measure) {
  double best = kInf;
  for (int k = 0; k <= steps; ++k) {
    const double tau = lo + (hi - lo) * k / static_cast<double>(steps);
    best = std::min(best, measure(JointVector(c.line.p + tau * c.line.n)));
  }
  return best;
}

// The cost of each resolution along a fine sweep of tau over [lo, hi], its minimum.
double swept_minimum(Resolution r, const Case& c, double lo, double hi) {
  return swept_minimum(c, lo, hi, 20000, [&](const JointVector& f) {
    return resolution_cost(k70m(), r, f, c.arms, &c.force);
  });
}

// The largest share of its position bound a joint rate takes.
double position_share(const JointRateBounds& position, const JointVector& f) {
  double share = 0.0;
  for (int i = 0; i < 4; ++i) {
    share = std::max(share, f[i] > 0 ? f[i] / position.upper[i] : f[i] / position.lower[i]);
  }
  return share;
}

// f meets the task: J f = u.
void expect_meets_the_task(const Case& c, const JointVector& f) {
  EXPECT_LT((c.jacobian * f - c.u).norm(), 1e-9 * (1.0 + f.norm()));
}

NullSpaceResult resolve(Resolution r, const NullSpaceProblem& p) {
  NullSpaceResult out;
  resolve_null_space(k70m(), r, p, out);
  return out;
}

// The problem with a symmetric hydraulic box and no other bounds.
NullSpaceProblem problem_for(const Case& c, double hydraulic_bound) {
  NullSpaceProblem p = problem_for(c);
  p.hydraulic = box(hydraulic_bound);
  return p;
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
  int compared = 0;
  const auto cases = cases_on_their_lines(2, 100);
  for (std::size_t trial = 0; trial < cases.size(); ++trial) {
    const Case& c = cases[trial];
    // A finite hydraulic box keeps the problem bounded (as the controller's always is).
    NullSpaceProblem p = problem_for(c, 20.0);
    for (Resolution r : kAll) {
      const NullSpaceResult out = resolve(r, p);
      ASSERT_EQ(out.status, NullSpaceStatus::kOptimal);
      expect_meets_the_task(c, out.f);
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
    const JointRateBounds loose = box(20.0);
    in.bounds = &loose;
    for (Resolution r :
         {Resolution::kPinvActuator, Resolution::kMinFlow, Resolution::kMinLsPower}) {
      ExtensionResolutionResult ext;
      resolve_by_extension(k70m(), r, in, ext);
      const NullSpaceResult out = resolve(r, p);
      if (!ext.feasible) continue;
      EXPECT_NEAR(out.cost, ext.cost, 1e-7 * (1.0 + std::abs(ext.cost))) << to_string(r);
      ++compared;
    }
    // pinv-joint: the minimum-norm solution itself.
    const NullSpaceResult out = resolve(Resolution::kPinvJoint, p);
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
    NullSpaceProblem p = problem_for(c, 50.0);
    for (int i = 0; i < 4; ++i) {
      p.position.upper[i] = width(rng);
      p.position.lower[i] = -width(rng);
    }
    for (Resolution r : kAll) {
      const NullSpaceResult out = resolve(r, p);
      expect_meets_the_task(c, out.f);
      // Feasible somewhere on the line (a sweep finds it)?
      const double best_share = swept_minimum(c, -50.0, 50.0, 40000, [&](const JointVector& f) {
        return position_share(p.position, f);
      });
      const double share = position_share(p.position, out.f);
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
    NullSpaceProblem p = problem_for(c, 50.0);
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
      const NullSpaceResult out = resolve(r, p);
      const double towards = upper ? out.f[at_end] : -out.f[at_end];
      EXPECT_LE(towards, 1e-9) << to_string(r) << " joint " << at_end;
      ++checked;
    }
  }
  EXPECT_GT(checked, 500);
}

TEST(NullSpaceResolution, HydraulicFallbackMaximisesTheSpeedTheCylindersAllow) {
  int fallbacks = 0;
  for (const Case& c : cases_on_their_lines(5, 300)) {
    NullSpaceProblem p = problem_for(c);
    // Cylinder-speed bounds of the K70M at a path speed of 2 m/s: often infeasible.
    for (int i = 0; i < 4; ++i) {
      const double rate = k70m().cylinders[i].v_max_m_s / std::abs(c.arms[i]) / 2.0;
      p.hydraulic.upper[i] = rate;
      p.hydraulic.lower[i] = -rate;
    }
    p.flow_limit_m2 = k70m().pump.max_flow_m3_s / 2.0;
    const NullSpaceResult out = resolve(Resolution::kMinLsPower, p);
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
    const double best = swept_minimum(c, out.hard_lo, out.hard_hi, 40000, load);
    EXPECT_GT(best, 1.0);
    EXPECT_LE(load(out.f), best * (1 + 1e-4));
  }
  EXPECT_GT(fallbacks, 20);
}

TEST(NullSpaceResolution, EndAvoidanceHandsMotionToTheOtherJoints) {
  int reduced = 0, trials = 0;
  for (const Case& c : cases_on_their_lines(6, 200)) {
    NullSpaceProblem p = problem_for(c, 20.0);
    for (Resolution r : kAll) {
      const NullSpaceResult plain = resolve(r, p);
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
      const NullSpaceResult out = resolve(r, avoid);
      ++trials;
      EXPECT_LE(std::abs(out.f[i]), std::abs(plain.f[i]) + 1e-12) << to_string(r);
      reduced += std::abs(out.f[i]) < 0.9 * std::abs(plain.f[i]);
      expect_meets_the_task(c, out.f);
    }
  }
  EXPECT_GT(trials, 100);
  EXPECT_GT(reduced, trials / 2);
}

TEST(NullSpaceResolution, HandoverBoundsYieldToTheHardOnes) {
  // Hand-over bounds tighter than anything feasible: the solution stays within the position and
  // hydraulic bounds and says the hand-over bound is exceeded.
  int handovers = 0;
  for (const Case& c : cases_on_their_lines(7, 200)) {
    NullSpaceProblem p = problem_for(c, 20.0);
    p.position = box(5.0);
    p.handover = box(1e-3);
    const NullSpaceResult out = resolve(Resolution::kMinFlow, p);
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
    NullSpaceProblem p = problem_for(c, 2.0);
    p.flow_limit_m2 = 1e-3;
    p.handover = box(0.1);
    p.avoid_weight = JointVector::Constant(4, 1.0);
    p.avoid_sign = JointVector::Constant(4, 1.0);
    for (Resolution r : kAll) resolve_null_space(k70m(), r, p, out);
  }
  EXPECT_EQ(craneassist::test::heap_allocations() - before, 0);
}
