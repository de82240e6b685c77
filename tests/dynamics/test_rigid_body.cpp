// RigidBodyTerms (H, C qdot, g probed from the ODE model) against an independent recursive
// Newton-Euler implementation, and OdeCrane's state mapping, efforts and end stops.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <numbers>
#include <random>
#include <thread>
#include <vector>

#include "allocation_counter.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/ode_crane.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "ode_allocation_counter.hpp"
#include "rnea_reference.hpp"

namespace {

using craneassist::dynamics::Body;
using craneassist::dynamics::CraneModel;
using craneassist::dynamics::DhJoint;
using craneassist::dynamics::DynamicsTerms;
using craneassist::dynamics::JointMatrix;
using craneassist::dynamics::JointType;
using craneassist::dynamics::JointVector;
using craneassist::dynamics::OdeCrane;
using craneassist::dynamics::RigidBodyTerms;

using craneassist::test::body;
using craneassist::test::joint;
using craneassist::test::k70m;
using craneassist::test::planar_2r;
using craneassist::test::random_q;
using craneassist::test::random_qdot;
using craneassist::test::Reference;
using craneassist::test::reference_terms;
using craneassist::test::relative_error;

constexpr double kPi = std::numbers::pi;

// Max relative errors over all comparisons, printed at the end of the comparison tests.
struct ErrorLog {
  double mass = 0, gravity = 0, coriolis = 0;
};

void compare_with_rnea(const CraneModel& model, unsigned seed, ErrorLog& log) {
  RigidBodyTerms terms(model);
  std::mt19937 rng(seed);
  DynamicsTerms out;
  for (int trial = 0; trial < 25; ++trial) {
    const JointVector q = random_q(model, rng);
    // Slow, moderate and fast motion (a K70M telescope at 2.5 m/s and the slew at 5 rad/s are
    // beyond the real machine, so the centripetal terms are far from negligible).
    const double scale = trial % 3 == 0 ? 0.3 : (trial % 3 == 1 ? 1.5 : 5.0);
    const JointVector qd = random_qdot(model, rng, scale);
    terms.compute(q, qd, out);
    const Reference ref = reference_terms(model, q, qd);
    SCOPED_TRACE(::testing::Message() << model.name << " trial " << trial << " q " << q.transpose()
                                      << " qdot " << qd.transpose());

    const double e_mass = relative_error(out.mass, ref.mass);
    const double e_gravity = relative_error(out.gravity, ref.gravity);
    const double e_coriolis = relative_error(out.coriolis, ref.coriolis);
    EXPECT_LT(e_mass, 1e-6);
    EXPECT_LT(e_gravity, 1e-6);
    EXPECT_LT(e_coriolis, 1e-6);
    log.mass = std::max(log.mass, e_mass);
    log.gravity = std::max(log.gravity, e_gravity);
    log.coriolis = std::max(log.coriolis, e_coriolis);

    // H symmetric positive definite.
    EXPECT_LT((out.mass - out.mass.transpose()).norm(), 1e-12 * out.mass.norm());
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd(out.mass));
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);

    // The separate entry points agree with compute().
    JointMatrix mass;
    JointVector gravity, coriolis;
    terms.mass_matrix(q, mass);
    terms.gravity(q, gravity);
    terms.coriolis(q, qd, coriolis);
    EXPECT_LT(relative_error(mass, out.mass), 1e-12);
    EXPECT_LT(relative_error(gravity, out.gravity), 1e-12);
    EXPECT_LT(relative_error(coriolis, out.coriolis), 1e-12);
  }
}

TEST(RigidBodyTerms, MatchesNewtonEulerOnK70M) {
  ErrorLog log;
  compare_with_rnea(k70m(650.0), 1u, log);
  std::printf("K70M loaded: max relative error H %.2e, g %.2e, C qdot %.2e\n", log.mass,
              log.gravity, log.coriolis);
}

TEST(RigidBodyTerms, MatchesNewtonEulerOnEmptyK70M) {
  ErrorLog log;
  compare_with_rnea(k70m(0.0), 2u, log);  // a zero-mass payload body must be accepted
  std::printf("K70M empty: max relative error H %.2e, g %.2e, C qdot %.2e\n", log.mass, log.gravity,
              log.coriolis);
}

TEST(RigidBodyTerms, MatchesNewtonEulerOnPlanar2R) {
  ErrorLog log;
  compare_with_rnea(planar_2r(), 3u, log);
  std::printf("planar 2R: max relative error H %.2e, g %.2e, C qdot %.2e\n", log.mass, log.gravity,
              log.coriolis);
}

TEST(RigidBodyTerms, Planar2RClosedForm) {
  // Textbook 2R terms with point-mass-plus-rod links, as a check on the reference itself.
  const CraneModel model = planar_2r();
  RigidBodyTerms terms(model);
  const double m1 = 20, m2 = 12, mt = 5, l1 = 1.0, l2 = 0.8;
  const double i1 = m1 * l1 * l1 / 12, i2 = m2 * l2 * l2 / 12;
  const double lc1 = 0.5, lc2 = 0.4;
  const double g = 9.81;
  JointVector q(2), qd(2);
  q << 0.7, -1.1;
  qd << 1.3, -2.2;
  DynamicsTerms out;
  terms.compute(q, qd, out);
  const double c2 = std::cos(q[1]), s2 = std::sin(q[1]);
  // Link 2 plus tip mass as one body: mass m2 + mt, first moment about the elbow.
  const double mb = m2 + mt, sb = m2 * lc2 + mt * l2, jb = i2 + m2 * lc2 * lc2 + mt * l2 * l2;
  const double h11 = i1 + m1 * lc1 * lc1 + mb * l1 * l1 + jb + 2 * l1 * sb * c2;
  const double h12 = jb + l1 * sb * c2;
  const double h22 = jb;
  const double hh = -l1 * sb * s2;
  const double c_1 = hh * (2 * qd[0] * qd[1] + qd[1] * qd[1]);
  const double c_2 = -hh * qd[0] * qd[0];
  const double g_1 = g * (m1 * lc1 + mb * l1) * std::cos(q[0]) + g * sb * std::cos(q[0] + q[1]);
  const double g_2 = g * sb * std::cos(q[0] + q[1]);
  EXPECT_NEAR(out.mass(0, 0), h11, 1e-9 * h11);
  EXPECT_NEAR(out.mass(0, 1), h12, 1e-9 * h11);
  EXPECT_NEAR(out.mass(1, 1), h22, 1e-9 * h11);
  EXPECT_NEAR(out.coriolis[0], c_1, 1e-7 * std::abs(c_1));
  EXPECT_NEAR(out.coriolis[1], c_2, 1e-7 * std::abs(c_2));
  EXPECT_NEAR(out.gravity[0], g_1, 1e-9 * std::abs(g_1));
  EXPECT_NEAR(out.gravity[1], g_2, 1e-9 * std::abs(g_1));
}

TEST(RigidBodyTerms, ZeroVelocityGivesZeroCoriolis) {
  RigidBodyTerms terms(k70m());
  JointVector q(4);
  q << 0.3, 0.5, -1.2, 1.5;
  DynamicsTerms out;
  terms.compute(q, JointVector::Zero(4), out);
  EXPECT_EQ(out.coriolis.size(), 4);
  EXPECT_EQ(out.coriolis.norm(), 0.0);
}

TEST(RigidBodyTerms, ComputeDoesNotAllocate) {
  const CraneModel model = k70m();
  RigidBodyTerms terms(model);
  std::mt19937 rng(7);
  std::vector<JointVector> qs, qds;
  for (int k = 0; k < 20; ++k) {
    qs.push_back(random_q(model, rng));
    qds.push_back(random_qdot(model, rng, 2.0));
  }
  DynamicsTerms out;
  out.mass.resize(4, 4);
  // ODE's own allocations too.
  craneassist::test::expect_no_heap_or_ode_allocations(model, [&] {
    for (int k = 0; k < 20; ++k) terms.compute(qs[k], qds[k], out);
  });
}

TEST(RigidBodyTerms, InstancesRunInParallelThreads) {
  // ODE worlds share one default threading implementation unless given their own; parallel steps
  // then abort inside ODE. RigidBodyTerms gives its world its own.
  const CraneModel model = k70m();
  JointVector q(4), qd(4);
  q << 0.3, 0.5, -1.2, 1.5;
  qd << 0.5, -0.4, 0.8, 0.3;
  DynamicsTerms ref;
  {
    RigidBodyTerms terms(model);
    terms.compute(q, qd, ref);
  }
  std::array<double, 3> deviation{};
  std::vector<std::thread> threads;
  for (size_t k = 0; k < deviation.size(); ++k) {
    threads.emplace_back([&, k] {
      RigidBodyTerms terms(model);
      DynamicsTerms out;
      for (int r = 0; r < 300; ++r) {
        terms.compute(q, qd, out);
        deviation[k] = std::max({deviation[k], relative_error(out.mass, ref.mass),
                                 relative_error(out.gravity, ref.gravity),
                                 relative_error(out.coriolis, ref.coriolis)});
      }
    });
  }
  for (std::thread& t : threads) t.join();
  for (const double d : deviation) EXPECT_LT(d, 1e-12);
}

TEST(RigidBodyTerms, ComputeTime) {
  const CraneModel model = k70m();
  RigidBodyTerms terms(model);
  std::mt19937 rng(11);
  DynamicsTerms out;
  const JointVector q = random_q(model, rng);
  const JointVector qd = random_qdot(model, rng, 1.0);
  const int reps = 300;
  double sink = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < reps; ++k) {
    terms.compute(q, qd, out);
    sink += out.coriolis[1];
  }
  const auto t1 = std::chrono::steady_clock::now();
  for (int k = 0; k < reps; ++k) {
    terms.compute(q, JointVector::Zero(4), out);
    sink += out.gravity[1];
  }
  const auto t2 = std::chrono::steady_clock::now();
  const double moving = std::chrono::duration<double, std::micro>(t1 - t0).count() / reps;
  const double at_rest = std::chrono::duration<double, std::micro>(t2 - t1).count() / reps;
  std::printf("compute(): %.1f us with qdot != 0, %.1f us with qdot = 0 (%g)\n", moving, at_rest,
              sink * 0.0);
  EXPECT_GT(moving, 0.0);
}

// ---------------------------------------------------------------------------------------------
// OdeCrane

class OdeWorld : public ::testing::Test {
 protected:
  void SetUp() override {
    craneassist::dynamics::ensure_ode_initialized();
    world_ = dWorldCreate();
  }
  void TearDown() override { dWorldDestroy(world_); }
  dWorldID world_ = nullptr;
};

TEST_F(OdeWorld, SetStateThenReadStateRoundTrips) {
  for (const CraneModel& model : {k70m(), planar_2r()}) {
    std::mt19937 rng(5);
    // Create away from mid-range so the stored reference matters.
    JointVector q_initial(model.dof());
    for (int i = 0; i < model.dof(); ++i) {
      q_initial[i] = model.joints[i].q_min + 0.1 * (model.joints[i].q_max - model.joints[i].q_min);
    }
    OdeCrane crane(model, world_, q_initial);
    JointVector q, qd;
    crane.read_state(q, qd);
    EXPECT_LT((q - q_initial).norm(), 1e-12);
    EXPECT_LT(qd.norm(), 1e-12);
    for (int trial = 0; trial < 50; ++trial) {
      const JointVector q_set = random_q(model, rng);
      const JointVector qd_set = random_qdot(model, rng, 3.0);
      crane.set_state(q_set, qd_set);
      crane.read_state(q, qd);
      EXPECT_LT((q - q_set).lpNorm<Eigen::Infinity>(), 1e-12) << model.name << " " << trial;
      EXPECT_LT((qd - qd_set).lpNorm<Eigen::Infinity>(), 1e-12) << model.name << " " << trial;
      crane.read_rates_at_set_pose(qd);
      EXPECT_LT((qd - qd_set).lpNorm<Eigen::Infinity>(), 1e-12) << model.name << " " << trial;
    }
  }
}

TEST_F(OdeWorld, SliderRateIsExactWithCentresOfMassOffTheAxis) {
  // A slider whose bodies' centres of mass are off the slider axis, on a turning base: ODE's
  // dJointGetSliderPositionRate would include omega x (com offset); read_state must not.
  CraneModel model;
  model.joints = {
      joint("turn", JointType::kRevolute, 0.5, kPi / 2, 0.3, 0.0, -kPi, kPi),
      joint("slide", JointType::kPrismatic, 0.0, 0.0, 1.0, 0.0, 0.0, 2.0),
  };
  model.bodies = {body("base arm", 1, 10, {0.2, 0.3, -0.1}, {1, 1, 1}),
                  body("slide", 2, 5, {0.4, -0.3, 0.2}, {0.5, 0.5, 0.5})};
  model.gravity_m_s2 = Eigen::Vector3d(0, -9.81, 0);  // loads both joints
  JointVector q(2), qd(2);
  q << 0.4, 0.7;
  qd << 2.0, 0.3;
  OdeCrane crane(model, world_, q);
  crane.set_state(q, qd);
  JointVector q_read, qd_read;
  crane.read_state(q_read, qd_read);
  EXPECT_NEAR(qd_read[1], 0.3, 1e-12);
  EXPECT_NEAR(q_read[1], 0.7, 1e-12);
  // And the probe handles it: compare with the reference.
  RigidBodyTerms terms(model);
  DynamicsTerms out;
  terms.compute(q, qd, out);
  const Reference ref = reference_terms(model, q, qd);
  EXPECT_LT(relative_error(out.mass, ref.mass), 1e-6);
  EXPECT_LT(relative_error(out.gravity, ref.gravity), 1e-6);
  EXPECT_LT(relative_error(out.coriolis, ref.coriolis), 1e-6);
}

TEST_F(OdeWorld, FreeFallMatchesMinusHInverseG) {
  // A world with the simulator's kind of settings (ERP 0.2): the first step from rest gives
  // qddot = -H^-1 g, exactly with rigid joints (CFM = 0) and up to the constraint softening with
  // ODE's default CFM (1e-10 in double precision, about 3e-4 relative at dt = 1 ms). Rates read
  // with read_state() after the step use the moved geometry, which is inconsistent with the
  // velocities at O(dt^2) (a few 1e-6 relative here); read_rates_at_set_pose() is exact.
  const CraneModel model = k70m();
  dWorldSetGravity(world_, 0, 0, -9.81);
  dWorldSetERP(world_, 0.2);
  for (const double cfm : {0.0, 1e-10}) {
    dWorldSetCFM(world_, cfm);
    std::mt19937 rng(9);
    double worst = 0.0, worst_at_set_pose = 0.0;
    for (int trial = 0; trial < 10; ++trial) {
      const JointVector q = random_q(model, rng);
      OdeCrane crane(model, world_, q);
      const double dt = 1e-3;
      ASSERT_NE(dWorldStep(world_, dt), 0);
      JointVector q_read, qd;
      const Reference ref = reference_terms(model, q, JointVector::Zero(4));
      const JointVector expected = -ref.mass.llt().solve(ref.gravity);
      crane.read_state(q_read, qd);
      worst = std::max(worst, relative_error(qd / dt, expected));
      crane.read_rates_at_set_pose(qd);
      worst_at_set_pose = std::max(worst_at_set_pose, relative_error(qd / dt, expected));
    }
    std::printf("free fall, CFM %g: max relative error %.2e (read_state), %.2e (at set pose)\n",
                cfm, worst, worst_at_set_pose);
    EXPECT_LT(worst, cfm == 0.0 ? 2e-5 : 1e-3);
    EXPECT_LT(worst_at_set_pose, cfm == 0.0 ? 1e-9 : 1e-3);
  }
}

TEST_F(OdeWorld, HoldingEffortKeepsTheCraneStill) {
  // add_joint_efforts(g) must cancel gravity: checks the sign conventions of the efforts and g.
  const CraneModel model = k70m();
  dWorldSetGravity(world_, 0, 0, -9.81);
  // Rigid joints: with ODE's default CFM (1e-10 in double precision) the joints give by CFM times
  // the constraint force, and at dt = 1 ms this crane then sags at about 0.01 rad/s^2 (linear in
  // CFM) even though the efforts balance gravity exactly.
  dWorldSetCFM(world_, 0.0);
  RigidBodyTerms terms(model);
  JointVector q(4);
  q << 0.8, 0.6, -1.4, 2.5;
  OdeCrane crane(model, world_, q);
  JointVector g;
  terms.gravity(q, g);
  crane.add_joint_efforts(g);
  const double dt = 1e-3;
  ASSERT_NE(dWorldStep(world_, dt), 0);
  JointVector q_read, qd;
  crane.read_state(q_read, qd);
  const Reference ref = reference_terms(model, q, JointVector::Zero(4));
  const JointVector free_fall = -ref.mass.llt().solve(ref.gravity);
  EXPECT_LT((qd / dt).norm(), 1e-6 * free_fall.norm()) << (qd / dt).transpose();
}

TEST_F(OdeWorld, EndStopsHold) {
  const CraneModel model = k70m();
  dWorldSetGravity(world_, 0, 0, -9.81);
  JointVector q(4);
  q << 3.0, 1.0, -0.4, 3.5;  // near the upper stops; slew near the +-pi wrap
  OdeCrane crane(model, world_, q);
  crane.enable_end_stops(true);
  RigidBodyTerms terms(model);
  JointVector push(4);
  push << 5e3, 1e5, 5e4, 2e4;  // drive every joint towards its upper stop, hard
  JointVector q_read, qd, g;
  double q_max_seen[4] = {-1e9, -1e9, -1e9, -1e9};
  for (int k = 0; k < 2000; ++k) {
    crane.read_state(q_read, qd);
    terms.gravity(q_read, g);
    crane.add_joint_efforts(g + push);
    ASSERT_NE(dWorldStep(world_, 1e-3), 0);
    for (int i = 0; i < 4; ++i) q_max_seen[i] = std::max(q_max_seen[i], q_read[i]);
  }
  crane.read_state(q_read, qd);
  // At rest against the stops (slew at pi - margin, not wrapped past pi).
  EXPECT_NEAR(q_read[0], kPi - OdeCrane::kHingeStopMargin, 0.02);
  EXPECT_NEAR(q_read[1], model.joints[1].q_max, 0.02);
  EXPECT_NEAR(q_read[2], model.joints[2].q_max, 0.02);
  EXPECT_NEAR(q_read[3], model.joints[3].q_max, 0.02);
  for (int i = 0; i < 4; ++i) EXPECT_LT(q_max_seen[i], model.joints[i].q_max + 0.02) << i;
  EXPECT_LT(qd.norm(), 1e-2);

  // Off again: the same push drives the extension past its stop.
  crane.enable_end_stops(false);
  for (int k = 0; k < 200; ++k) {
    crane.read_state(q_read, qd);
    terms.gravity(q_read, g);
    JointVector e = g;
    e[3] += push[3];
    crane.add_joint_efforts(e);
    ASSERT_NE(dWorldStep(world_, 1e-3), 0);
  }
  crane.read_state(q_read, qd);
  EXPECT_GT(q_read[3], model.joints[3].q_max + 0.05);
}

TEST_F(OdeWorld, MassMergingAndPlacement) {
  const CraneModel model = k70m(650.0);
  JointVector q(4);
  q << 0.2, 0.4, -1.0, 1.0;
  OdeCrane crane(model, world_, q);
  ASSERT_EQ(crane.dof(), 4);
  EXPECT_DOUBLE_EQ(crane.mass(4), 160.0 + 180.0 + 650.0);
  EXPECT_NEAR(crane.com_local(4).y(), 160.0 * 1.85 / 990.0, 1e-15);
  // Body 4 sits at o_4 + R_4 com_4 with orientation R_4.
  const Eigen::Isometry3d& f4 = crane.kinematics().frames[4];
  const Eigen::Vector3d p = f4 * crane.com_local(4);
  const dReal* pos = dBodyGetPosition(crane.body(4));
  EXPECT_LT((Eigen::Vector3d(pos[0], pos[1], pos[2]) - p).norm(), 1e-12);
  const dReal* r = dBodyGetRotation(crane.body(4));
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) EXPECT_NEAR(r[4 * row + col], f4.linear()(row, col), 1e-12);
  }
  dMass m;
  dBodyGetMass(crane.body(3), &m);
  EXPECT_DOUBLE_EQ(m.mass, 300.0);
  EXPECT_DOUBLE_EQ(m.I[0], 156.0);
  EXPECT_DOUBLE_EQ(m.I[10], 8.0);
}

TEST_F(OdeWorld, EmptyFrameGetsPlaceholderMass) {
  CraneModel model = planar_2r();
  model.bodies.erase(model.bodies.begin());  // nothing on frame 1
  OdeCrane crane(model, world_, JointVector::Zero(2));
  EXPECT_DOUBLE_EQ(crane.mass(1), OdeCrane::kEmptyFrameMassKg);
}

}  // namespace
