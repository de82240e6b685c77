// Uniform flow prescaling: the factor, the limit it reports, and that the direction is kept.
#include <gtest/gtest.h>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/scaling/flow_prescaling.hpp"

using namespace craneassist;
using dynamics::JointVector;

namespace {

struct Fixture {
  dynamics::CraneModel model = config::default_crane_config().model;
  JointVector arms = JointVector::Ones(4);  // dc/dq = 1: joint rates are cylinder velocities
};

}  // namespace

TEST(FlowPrescaling, WithinLimitsNothingChanges) {
  Fixture f;
  JointVector qdot(4);
  qdot << 0.01, 0.02, -0.02, 0.05;
  scaling::FlowPrescalingResult r;
  scaling::flow_prescale(f.model, f.arms, qdot, 0.0, r);
  EXPECT_DOUBLE_EQ(r.scale, 1.0);
  EXPECT_EQ(r.limit, scaling::ActiveLimit::kNone);
  const auto& c = f.model.cylinders;
  const double expected = 0.01 * c[0].area_a_m2 + 0.02 * c[1].area_a_m2 + 0.02 * c[2].area_b_m2 +
                          0.05 * (c[3].area_a_m2 - c[3].area_b_m2);
  EXPECT_NEAR(r.flow_demand_m3_s, expected, 1e-15);
}

TEST(FlowPrescaling, CylinderSpeedLimitNamesTheCylinder) {
  Fixture f;
  JointVector qdot(4);
  qdot << 0.0, 0.3, 0.0, 0.1;  // lift at twice its 0.15 m/s
  scaling::FlowPrescalingResult r;
  scaling::flow_prescale(f.model, f.arms, qdot, 0.0, r);
  EXPECT_NEAR(r.scale, 0.5, 1e-12);
  EXPECT_EQ(r.limit, scaling::ActiveLimit::kCylinderSpeed);
  EXPECT_EQ(r.limiting_cylinder, 1);
}

TEST(FlowPrescaling, PumpFlowLimitWithReserve) {
  Fixture f;
  f.model.pump.max_flow_m3_s = 1e-3;
  JointVector qdot(4);
  qdot << 0.05, 0.1, -0.1, 0.0;  // within every cylinder's speed
  scaling::FlowPrescalingResult r;
  scaling::flow_prescale(f.model, f.arms, qdot, 0.1, r);
  EXPECT_EQ(r.limit, scaling::ActiveLimit::kFlow);
  EXPECT_NEAR(r.scale * r.flow_demand_m3_s, 0.9e-3, 1e-15);
  // The scaled reference needs exactly the budget: same direction, smaller magnitude.
  const JointVector scaled = qdot * r.scale;
  EXPECT_NEAR(dynamics::pump_flow_demand(f.model, scaled), 0.9e-3, 1e-15);
}

TEST(FlowPrescaling, BothLimitsTakeTheSmallerFactor) {
  Fixture f;
  f.model.pump.max_flow_m3_s = 1e-3;
  JointVector qdot(4);
  qdot << 0.0, 0.3, 0.0, 0.0;  // 0.15/0.3 = 0.5 by speed; 1e-3/(0.3*A) = 0.29 by flow
  scaling::FlowPrescalingResult r;
  scaling::flow_prescale(f.model, f.arms, qdot, 0.0, r);
  EXPECT_EQ(r.limit, scaling::ActiveLimit::kFlow);
  EXPECT_NEAR(r.scale, 1e-3 / (0.3 * f.model.cylinders[1].area_a_m2), 1e-12);
}
