// The controller's tip-scaling stages on their own (control/tip_stage.hpp) and the polytope as an
// observer: the full scaling's reference follows the command's direction, integrates along the
// path and stops jerk-limited on a stale input; the baselines stop at once and keep the pump's
// flow; the polytope changes nothing the machine is told, and is computed only when asked for.
#include <gtest/gtest.h>

#include <cmath>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/controller.hpp"
#include "craneassist/control/tip_stage.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/hydraulics.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "still_state.hpp"

using namespace craneassist;

namespace {

using test::still_state;

// A stage on a machine that is exactly at its reference, with no load on the chart.
struct StageRig {
  config::CraneConfig cfg = config::default_crane_config();
  std::unique_ptr<control::TipStage> stage;
  valves::MachineState state = still_state(cfg);
  control::ControllerOutput out;
  control::LoadOutput load;

  explicit StageRig(control::ScalingMode mode) : stage(control::make_tip_stage(cfg, mode)) {
    stage->reset(state.q);
  }
  control::TipStageStatus step(const Eigen::Vector3d& v, bool stale = false) {
    const dynamics::JointVector delayed = stage->q_ref();
    out.load = load;
    const control::TipStageInput in{.command = v,
                                    .stale = stale,
                                    .state = &state,
                                    .delayed_q_ref = &delayed,
                                    .load = &out.load};
    const auto status = stage->update(in, out);
    state.q = out.q_ref;
    return status;
  }
};

}  // namespace

TEST(PathScalingStage, ReferenceAlongTheCommandAndIntegratedAlongThePath) {
  StageRig rig(control::ScalingMode::kFull);
  const Eigen::Vector3d v(0.3, 0.2, -0.25);
  dynamics::KinematicsData kin;
  dynamics::TaskJacobian jacobian;
  const double dt = 1.0 / rig.cfg.control.rate_hz;
  ASSERT_EQ(rig.stage->q_ref(), rig.cfg.simulation.q_initial);
  for (int k = 0; k < 150; ++k) {
    const dynamics::JointVector q_before = rig.stage->q_ref();
    const Eigen::Vector3d tip_before = dynamics::tip_position(rig.cfg.model, kin, q_before);
    ASSERT_EQ(rig.step(v), control::TipStageStatus::kMoving) << k;
    const auto& out = rig.out;
    // The reference velocity lies along the command (one factor on the whole motion) ...
    if (out.ref_tip_velocity_m_s.norm() > 1e-6) {
      EXPECT_NEAR(out.ref_tip_velocity_m_s.normalized().dot(v.normalized()), 1.0, 1e-9) << k;
    }
    EXPECT_GE(out.scale, 0.0);
    EXPECT_LE(out.scale, 1.0);
    // ... is J(q) qdot_ref at the pose it was resolved at ...
    dynamics::tip_jacobian(rig.cfg.model, kin, q_before, jacobian);
    EXPECT_LT((jacobian * out.qdot_ref - out.ref_tip_velocity_m_s).norm(), 1e-9) << k;
    // ... and the resolved motion is f': J f' = u, tip speed 1 per unit path speed.
    EXPECT_EQ(rig.stage->resolved_tip_speed(), 1.0);
    // The tip moved along the command by what the cycle covered.
    const Eigen::Vector3d moved =
        dynamics::tip_position(rig.cfg.model, kin, out.q_ref) - tip_before;
    EXPECT_LT((moved - v.normalized() * v.normalized().dot(moved)).norm(), 1e-5) << k;
    EXPECT_LE(moved.norm(), out.sdot * dt + 1e-4) << k;
  }
  EXPECT_GT(rig.out.sdot, 0.1);
  EXPECT_FALSE(rig.stage->dynamics_failed());
  ASSERT_NE(rig.stage->dynamics(), nullptr);
}

TEST(PathScalingStage, StaleInputStopsJerkLimitedThenRests) {
  StageRig rig(control::ScalingMode::kFull);
  const Eigen::Vector3d v(0.4, 0.0, 0.3);
  for (int k = 0; k < 200; ++k) rig.step(v);
  const double speed = rig.out.sdot;
  ASSERT_GT(speed, 0.1);
  const double dt = 1.0 / rig.cfg.control.rate_hz;
  const double decel = rig.cfg.scaling.deceleration_max_m_s2;
  double last = speed;
  int cycles = 0;
  while (rig.step(Eigen::Vector3d::Zero(), true) == control::TipStageStatus::kMoving) {
    EXPECT_EQ(rig.out.limit, scaling::ActiveLimit::kStaleInput);
    EXPECT_LE(last - rig.out.sdot, decel * dt * 1.05 + 1e-9) << cycles;  // no velocity step
    last = rig.out.sdot;
    ASSERT_LT(++cycles, 1000);
  }
  EXPECT_GT(cycles, 5);  // not at once: jerk-limited
  EXPECT_EQ(rig.out.sdot, 0.0);
  EXPECT_TRUE(rig.out.qdot_ref.isZero(0.0));
  // Rest is held: the reference no longer moves.
  const dynamics::JointVector q = rig.stage->q_ref();
  EXPECT_EQ(rig.step(Eigen::Vector3d::Zero(), true), control::TipStageStatus::kAtRest);
  EXPECT_EQ(rig.stage->q_ref(), q);
}

TEST(PrescalingStage, StopsAtOnceAndKeepsThePumpsFlow) {
  StageRig rig(control::ScalingMode::kFlowOnly);
  const Eigen::Vector3d v(1.5, 1.0, -1.0);  // more than the pump gives
  dynamics::JointVector arms;
  const double budget = dynamics::flow_budget_m3_s(rig.cfg.model, rig.cfg.control.flow_reserve);
  for (int k = 0; k < 50; ++k) {
    const dynamics::JointVector q_before = rig.stage->q_ref();
    ASSERT_EQ(rig.step(v), control::TipStageStatus::kMoving);
    dynamics::cylinder_arms(rig.cfg.model, q_before, arms);
    EXPECT_LE(dynamics::joint_motion_flow_m3_s(rig.cfg.model, arms, rig.out.qdot_ref),
              budget * (1 + 1e-9));
    EXPECT_LT(rig.out.scale, 1.0);
    EXPECT_GT(rig.stage->resolved_tip_speed(), 0.0);
  }
  const dynamics::JointVector q = rig.stage->q_ref();
  EXPECT_EQ(rig.step(v, true), control::TipStageStatus::kAtRest);
  EXPECT_EQ(rig.out.limit, scaling::ActiveLimit::kStaleInput);
  EXPECT_EQ(rig.out.scale, 0.0);
  EXPECT_TRUE(rig.out.qdot_ref.isZero(0.0));
  EXPECT_EQ(rig.stage->q_ref(), q);
  EXPECT_TRUE(rig.stage->resolved_motion().isZero(0.0));
  EXPECT_EQ(rig.stage->dynamics(), nullptr);
}

TEST(PolytopeProbe, AnObserverThatChangesNothingTheMachineIsTold) {
  // The same run with and without the polytope: every valve command and reference bit for bit
  // the same; only the polytope's figures differ (zero without it).
  for (const auto mode : control::kScalingModes) {
    const auto cfg = config::default_crane_config();
    control::Controller with(cfg, {.mode = mode, .polytope = true});
    control::Controller without(cfg, {.mode = mode});
    valves::MachineState a = still_state(cfg), b = still_state(cfg);
    with.reset(a);
    without.reset(b);
    control::ControllerOutput out_a, out_b;
    for (int k = 0; k < 300; ++k) {
      const Eigen::Vector3d v = k < 200 ? Eigen::Vector3d(0.3, 0.2, 0.4) : Eigen::Vector3d::Zero();
      with.update(a, v, out_a);
      without.update(b, v, out_b);
      ASSERT_EQ(out_a.q_ref, out_b.q_ref) << k;
      ASSERT_EQ(out_a.valves.spool, out_b.valves.spool) << k;
      ASSERT_EQ(out_a.scale, out_b.scale) << k;
      ASSERT_EQ(out_a.limit, out_b.limit) << k;
      EXPECT_EQ(out_b.polytope_dim, 0);
      EXPECT_EQ(out_b.avail_speed_m_s, 0.0);
      EXPECT_EQ(out_a.polytope_dim, 3) << k;
      EXPECT_GT(out_a.avail_speed_m_s, 0.0) << k;
      a.q = out_a.q_ref;
      b.q = out_b.q_ref;
    }
    // Turned off, the figures stop; turned on again, they come back.
    with.set_polytope(false);
    with.update(a, Eigen::Vector3d::Zero(), out_a);
    control::ControllerOutput fresh;
    with.update(a, Eigen::Vector3d::Zero(), fresh);
    EXPECT_EQ(fresh.polytope_dim, 0);
    with.set_polytope(true);
    with.update(a, Eigen::Vector3d(0.1, 0.0, 0.0), fresh);
    EXPECT_EQ(fresh.polytope_dim, 3);
  }
}
