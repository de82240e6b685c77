// RigidBodyTerms::path_terms (m = H f', b = H f'' sdot^2 + C(q, f' sdot) f' sdot + g, the path
// dynamics of docs/algorithms.md section 3) against an independent recursive Newton-Euler
// implementation and against the compute()-based formula; no allocation in the control cycle.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <random>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "allocation_counter.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "ode_allocation_counter.hpp"
#include "rnea_reference.hpp"

namespace {

using craneassist::dynamics::CraneModel;
using craneassist::dynamics::DynamicsTerms;
using craneassist::dynamics::JointType;
using craneassist::dynamics::JointVector;
using craneassist::dynamics::PathTerms;
using craneassist::dynamics::RigidBodyTerms;
using craneassist::test::body;
using craneassist::test::joint;
using craneassist::test::k70m;
using craneassist::test::kPi;
using craneassist::test::planar_2r;
using craneassist::test::random_q;
using craneassist::test::random_qdot;
using craneassist::test::relative_error;
using craneassist::test::rnea;

// A slider whose bodies' centres of mass are off the slider axis, on a turning base (as in
// test_rigid_body.cpp): the slider's reaction read-out must not pick up the offset.
CraneModel turning_slider() {
  CraneModel model;
  model.name = "turning slider";
  model.joints = {
      joint("turn", JointType::kRevolute, 0.5, kPi / 2, 0.3, 0.0, -kPi, kPi),
      joint("slide", JointType::kPrismatic, 0.0, 0.0, 1.0, 0.0, 0.0, 2.0),
  };
  model.bodies = {body("base arm", 1, 10, {0.2, 0.3, -0.1}, {1, 1, 1}),
                  body("slide", 2, 5, {0.4, -0.3, 0.2}, {0.5, 0.5, 0.5})};
  model.gravity_m_s2 = Eigen::Vector3d(0, -9.81, 0);
  return model;
}

// Max relative errors over all comparisons of one model.
struct ErrorLog {
  double m = 0;         // m vs RNEA(q, 0, f', no gravity) = H f'
  double b = 0;         // b vs RNEA(q, f' sdot, f'' sdot^2, gravity)
  double dynamic = 0;   // b - g vs RNEA(q, f' sdot, f'' sdot^2, no gravity)
  double velocity = 0;  // b - g with f'' = 0 vs RNEA(q, f' sdot, 0, no gravity) = C qdot
};

void compare_with_rnea(const CraneModel& model, unsigned seed, ErrorLog& log) {
  RigidBodyTerms terms(model);
  const int n = model.dof();
  const JointVector zero = JointVector::Zero(n);
  const Eigen::Vector3d no_gravity = Eigen::Vector3d::Zero();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> speed(0.05, 1.0);
  PathTerms out;
  for (int trial = 0; trial < 40; ++trial) {
    const JointVector q = random_q(model, rng);
    // Path tangents of up to 1.5 rad (or 0.75 m) per unit path speed, derivatives of either sign,
    // and path speeds from slow to well beyond the machine (strong centripetal terms).
    const JointVector f1 = random_qdot(model, rng, 1.5);
    const JointVector f2 = random_qdot(model, rng, 2.0);
    const double sdot = speed(rng) * (trial % 4 == 3 ? 4.0 : 1.0);
    SCOPED_TRACE(::testing::Message()
                 << model.name << " trial " << trial << " q " << q.transpose() << " f' "
                 << f1.transpose() << " f'' " << f2.transpose() << " sdot " << sdot);

    ASSERT_TRUE(terms.path_terms(q, f1, f2, sdot, out));
    const JointVector gravity = rnea(model, q, zero, zero, model.gravity_m_s2);
    const double e_m = relative_error(out.m, rnea(model, q, zero, f1, no_gravity));
    const double e_b =
        relative_error(out.b, rnea(model, q, f1 * sdot, f2 * sdot * sdot, model.gravity_m_s2));
    const JointVector b_dynamic = out.b - gravity;
    const double e_dynamic =
        relative_error(b_dynamic, rnea(model, q, f1 * sdot, f2 * sdot * sdot, no_gravity));
    EXPECT_LT(e_m, 1e-6);
    EXPECT_LT(e_b, 1e-6);
    EXPECT_LT(e_dynamic, 1e-6);

    // Velocity products alone (f'' = 0): b - g = C(q, f' sdot) f' sdot.
    ASSERT_TRUE(terms.path_terms(q, f1, zero, sdot, out));
    const JointVector b_velocity = out.b - gravity;
    const double e_velocity =
        relative_error(b_velocity, rnea(model, q, f1 * sdot, zero, no_gravity));
    EXPECT_LT(e_velocity, 1e-6);

    log.m = std::max(log.m, e_m);
    log.b = std::max(log.b, e_b);
    log.dynamic = std::max(log.dynamic, e_dynamic);
    log.velocity = std::max(log.velocity, e_velocity);
  }
}

void print(const char* name, const ErrorLog& log) {
  std::printf("%s: max relative error m %.2e, b %.2e, b - g %.2e, C qdot %.2e\n", name, log.m,
              log.b, log.dynamic, log.velocity);
}

TEST(PathTerms, MatchesNewtonEulerOnK70M) {
  ErrorLog log;
  compare_with_rnea(k70m(650.0), 1u, log);
  print("K70M loaded", log);
}

TEST(PathTerms, MatchesNewtonEulerOnEmptyK70M) {
  ErrorLog log;
  compare_with_rnea(k70m(0.0), 2u, log);
  print("K70M empty", log);
}

TEST(PathTerms, MatchesNewtonEulerOnPlanar2R) {
  ErrorLog log;
  compare_with_rnea(planar_2r(), 3u, log);
  print("planar 2R", log);
}

TEST(PathTerms, MatchesNewtonEulerOnTurningSlider) {
  ErrorLog log;
  compare_with_rnea(turning_slider(), 4u, log);
  print("turning slider", log);
}

// A pose of the K70M, a path direction f' and its derivative f'' there.
std::tuple<JointVector, JointVector, JointVector> k70m_path_point() {
  JointVector q(4), f1(4), f2(4);
  q << 0.3, 0.5, -1.2, 1.5;
  f1 << 0.2, -0.4, 0.7, 0.3;
  f2 << 3.0, -2.0, 1.0, 5.0;
  return {q, f1, f2};
}

TEST(PathTerms, AtRestBIsGravity) {
  // sdot = 0: b = g whatever f'' is, and m does not depend on sdot.
  RigidBodyTerms terms(k70m());  // copies the model
  const auto [q, f1, f2] = k70m_path_point();
  PathTerms at_rest, moving;
  ASSERT_TRUE(terms.path_terms(q, f1, f2, 0.0, at_rest));
  ASSERT_TRUE(terms.path_terms(q, f1, f2, 0.8, moving));
  JointVector g;
  terms.gravity(q, g);
  EXPECT_LT(relative_error(at_rest.b, g), 1e-12);
  EXPECT_LT(relative_error(at_rest.m, moving.m), 1e-14);
  EXPECT_GT(relative_error(moving.b, g), 1e-3);  // the motion does show in b
}

TEST(PathTerms, AFailedStepIsAStatusNotAnException) {
  // dWorldStep fails only when ODE runs out of memory; the test hook fails every probe step the
  // same way. path_terms() (the control cycle's call) reports it; compute() (offline) throws.
  RigidBodyTerms terms(k70m());  // copies the model
  const auto [q, f1, f2] = k70m_path_point();
  PathTerms before, after;
  ASSERT_TRUE(terms.path_terms(q, f1, f2, 0.8, before));
  static_assert(noexcept(terms.path_terms(q, f1, f2, 0.8, after)));

  terms.fail_steps_for_testing(true);
  PathTerms failed;
  EXPECT_FALSE(terms.path_terms(q, f1, f2, 0.8, failed));
  EXPECT_FALSE(terms.path_terms(q, f1, f2, 0.0, failed));
  DynamicsTerms full;
  EXPECT_THROW(terms.compute(q, f1, full), std::runtime_error);

  // Nothing is left behind: the next good step gives the same terms as before.
  terms.fail_steps_for_testing(false);
  ASSERT_TRUE(terms.path_terms(q, f1, f2, 0.8, after));
  EXPECT_EQ(after.m, before.m);
  EXPECT_EQ(after.b, before.b);
}

TEST(PathTerms, AgreesWithComputeFormula) {
  // The slow way: H, C qdot and g from compute() at qdot = f' sdot, then the formula.
  for (const CraneModel& model : {k70m(650.0), planar_2r()}) {
    RigidBodyTerms terms(model);
    std::mt19937 rng(5);
    double worst_m = 0, worst_b = 0;
    for (int trial = 0; trial < 20; ++trial) {
      const JointVector q = random_q(model, rng);
      const JointVector f1 = random_qdot(model, rng, 1.0);
      const JointVector f2 = random_qdot(model, rng, 1.0);
      const double sdot = 0.1 + 0.1 * trial;
      DynamicsTerms full;
      terms.compute(q, f1 * sdot, full);
      const JointVector m = full.mass * f1;
      const JointVector b = full.mass * f2 * (sdot * sdot) + full.coriolis + full.gravity;
      PathTerms out;
      ASSERT_TRUE(terms.path_terms(q, f1, f2, sdot, out));
      worst_m = std::max(worst_m, relative_error(out.m, m));
      worst_b = std::max(worst_b, relative_error(out.b, b));
      // And path_terms() leaves compute() as it was (its motors are off again).
      DynamicsTerms again;
      terms.compute(q, f1 * sdot, again);
      EXPECT_LT(relative_error(again.mass, full.mass), 1e-14);
      EXPECT_LT(relative_error(again.gravity, full.gravity), 1e-14);
      EXPECT_LT(relative_error(again.coriolis, full.coriolis), 1e-14);
    }
    std::printf("%s: path_terms vs compute() formula, max relative error m %.2e, b %.2e\n",
                model.name.c_str(), worst_m, worst_b);
    EXPECT_LT(worst_m, 1e-10);
    EXPECT_LT(worst_b, 1e-6);  // compute()'s C qdot is a central difference (about 2e-8)
  }
}

TEST(PathTerms, DoesNotAllocate) {
  const CraneModel model = k70m();
  RigidBodyTerms terms(model);
  std::mt19937 rng(7);
  std::vector<JointVector> qs, f1s, f2s;
  for (int k = 0; k < 20; ++k) {
    qs.push_back(random_q(model, rng));
    f1s.push_back(random_qdot(model, rng, 1.0));
    f2s.push_back(random_qdot(model, rng, 1.0));
  }
  PathTerms out;
  out.m.resize(4);
  out.b.resize(4);
  DynamicsTerms full;
  full.mass.resize(4, 4);
  bool steps_ok = true;
  // ODE's own allocations too.
  craneassist::test::expect_no_heap_or_ode_allocations(model, [&] {
    for (int k = 0; k < 20; ++k) {
      steps_ok =
          terms.path_terms(qs[k], f1s[k], f2s[k], k % 5 == 0 ? 0.0 : 0.1 * k, out) && steps_ok;
      if (k % 7 == 0) terms.compute(qs[k], f1s[k], full);  // motors off and on again
    }
  });
  EXPECT_TRUE(steps_ok);
}

TEST(PathTerms, Time) {
  // Informative (bench_pipeline's BM_PathTerms is the measurement of record).
  const CraneModel model = k70m();
  RigidBodyTerms terms(model);
  std::mt19937 rng(11);
  const JointVector q = random_q(model, rng);
  const JointVector f1 = random_qdot(model, rng, 1.0);
  const JointVector f2 = random_qdot(model, rng, 1.0);
  PathTerms out;
  const int reps = 1000;
  double sink = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < reps; ++k) {
    ASSERT_TRUE(terms.path_terms(q, f1, f2, 0.7, out));
    sink += out.b[1];
  }
  const auto t1 = std::chrono::steady_clock::now();
  const double us = std::chrono::duration<double, std::micro>(t1 - t0).count() / reps;
  std::printf("path_terms(): %.1f us (%g)\n", us, sink * 0.0);
  EXPECT_GT(us, 0.0);
}

}  // namespace
