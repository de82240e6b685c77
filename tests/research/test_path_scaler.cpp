// paths::PathScaler on its own (it is otherwise reached through the 2R experiment): the
// planar 2R arm of paper 004 on its sine joint path f(s) = [pi/6 - sin s, -pi/6 - 0.5 sin s],
// stepped cycle by cycle with the reference's own geometry (no machine). Checks the scaler's
// promises: the path speed never exceeds the request or the velocity limits it reports, the
// path jerk and accelerations stay within their bounds, the model's load-sensing power stays
// within P_max, a stale input stops jerk-limited, and the tracking factor scales the speed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "craneassist/paths/path_scaler.hpp"
#include "craneassist/studies/sine_path_experiment.hpp"

using namespace craneassist;

namespace {

constexpr double kPeriod = 0.01;

class SinePathScaler : public ::testing::Test {
 protected:
  void SetUp() override {
    cfg_ = config::planar_2r_config();
    geometry_.d2c_dq2.resize(2);
  }

  paths::PathScalerConfig config(scaling::PowerBound bound) const {
    return {kPeriod, 1000.0, 100.0, cfg_.control.flow_reserve, bound, cfg_.scaling.power_reserve,
            100.0};
  }

  // The geometry at the path coordinate s.
  void geometry_at(double s) {
    studies::sine_path(s, q_, geometry_.f1, geometry_.f2);
    dynamics::cylinder_arms(cfg_.model, q_, geometry_.dc_dq);
    for (int i = 0; i < 2; ++i) {
      geometry_.d2c_dq2[i] =
          dynamics::cylinder_arm_slope(cfg_.model.cylinders[static_cast<std::size_t>(i)], q_[i]);
    }
  }

  void step(paths::PathScaler& scaler, const paths::PathScalerInput& in,
            paths::PathScalerOutput& out) {
    geometry_at(scaler.state().s);
    scaler.update(q_, geometry_, in, out);
  }

  // A path scaler on the fixture's crane with its own dynamics terms, asked for sdot_request.
  struct Scaler {
    Scaler(const dynamics::CraneModel& model, const paths::PathScalerConfig& config,
           double sdot_request)
        : terms(model), scaler(model, config, terms) {
      in.sdot_request = sdot_request;
    }
    dynamics::RigidBodyTerms terms;
    paths::PathScaler scaler;
    paths::PathScalerInput in;
    paths::PathScalerOutput out;
  };

  config::CraneConfig cfg_;
  scaling::PathGeometry geometry_;
  dynamics::JointVector q_;
};

}  // namespace

TEST_F(SinePathScaler, SpeedStaysWithinTheRequestAndItsLimitsAndJerkWithinItsBound) {
  Scaler s(cfg_.model, config(scaling::PowerBound::kLoadSensing), 2.0);
  auto& [terms, scaler, in, out] = s;
  double peak_sdot = 0.0;
  int limited = 0;
  for (int k = 0; k < 800; ++k) {
    step(scaler, in, out);
    const auto& st = out.state;
    ASSERT_TRUE(std::isfinite(st.sdot)) << k;
    EXPECT_LE(st.sdot, in.sdot_request + 1e-9) << k;
    EXPECT_LE(std::abs(st.sdddot), 1000.0 + 1e-6) << k;
    EXPECT_LE(st.sddot, 100.0 + 1e-6) << k;
    EXPECT_GE(st.sddot, -100.0 - 1e-6) << k;
    EXPECT_GE(st.sdot, 0.0) << k;
    // The speed request handed to the filter respects every velocity-level limit.
    EXPECT_LE(out.sdot_d, std::min(out.speed.sdot_flow, out.speed.sdot_cylinder) + 1e-9) << k;
    peak_sdot = std::max(peak_sdot, st.sdot);
    limited += out.limit != scaling::ActiveLimit::kNone;
  }
  EXPECT_GT(scaler.state().s, 2.0) << "the path was traversed";
  EXPECT_GT(peak_sdot, 0.5);
  EXPECT_GT(limited, 0) << "on this path at 2 rad/s something limits the speed";
}

// The paper's claim, at the model: with the load-sensing bound the pump power the reference
// needs stays within P_max; the older actuator-power-sum bound lets it exceed that. The bound
// uses P_max (1 - reserve) with m(s), b(s) from the start of each cycle, so the power of the
// state at the cycle's end may pass P_max (1 - reserve) by the change over one cycle (about 3 %
// of it on this path at 1000 1/s^3), which the reserve is for.
TEST_F(SinePathScaler, LoadSensingBoundKeepsTheModelsPumpPowerWithinPmax) {
  const double p_max = cfg_.model.pump.prime_mover_power_w;
  double peak[2] = {0.0, 0.0};
  const scaling::PowerBound bounds[2] = {scaling::PowerBound::kLoadSensing,
                                         scaling::PowerBound::kActuatorPowerSum};
  for (int b = 0; b < 2; ++b) {
    Scaler s(cfg_.model, config(bounds[b]), 2.0);
    auto& [terms, scaler, in, out] = s;
    for (int k = 0; k < 800; ++k) {
      step(scaler, in, out);
      // The power of the state the scaler chose, with the terms it used this cycle.
      const double p = scaling::load_sensing_power(cfg_.model, geometry_, out.terms, out.state.sdot,
                                                   out.state.sddot);
      peak[b] = std::max(peak[b], p);
    }
  }
  EXPECT_LE(peak[0], p_max * 1.01) << "load-sensing bound";
  EXPECT_GT(peak[1], p_max * 1.05) << "the actuator-power-sum bound lets the LS pump exceed P_max";
}

TEST_F(SinePathScaler, StaleInputStopsJerkLimitedAndStaysStopped) {
  Scaler s(cfg_.model, config(scaling::PowerBound::kLoadSensing), 1.0);
  auto& [terms, scaler, in, out] = s;
  for (int k = 0; k < 200; ++k) step(scaler, in, out);
  ASSERT_GT(out.state.sdot, 0.3);
  in.sdot_request = 0.0;
  in.stale_input = true;
  int k_stop = -1;
  double last_sddot = out.state.sddot;
  for (int k = 0; k < 300; ++k) {
    step(scaler, in, out);
    EXPECT_EQ(out.limit, scaling::ActiveLimit::kStaleInput) << k;
    EXPECT_LE(std::abs(out.state.sddot - last_sddot), 1000.0 * kPeriod + 1e-6) << k;
    last_sddot = out.state.sddot;
    EXPECT_GE(out.state.sdot, 0.0) << "a stop never turns into a reversal";
    if (k_stop < 0 && out.state.sdot == 0.0 && out.state.sddot == 0.0) k_stop = k;
  }
  ASSERT_GE(k_stop, 0) << "came to rest";
  EXPECT_LT(k_stop, 100) << "within a second";
  EXPECT_EQ(out.filter_status, scaling::ScalingFilterStatus::kStopped);
  EXPECT_EQ(out.state.sdot, 0.0);
}

TEST_F(SinePathScaler, TrackingFactorScalesTheSpeed) {
  double steady[2] = {0.0, 0.0};
  const double factors[2] = {1.0, 0.5};
  for (int f = 0; f < 2; ++f) {
    // 0.3: slow enough that no hydraulic limit holds it back.
    Scaler s(cfg_.model, config(scaling::PowerBound::kNone), 0.3);
    auto& [terms, scaler, in, out] = s;
    in.tracking_factor = factors[f];
    for (int k = 0; k < 150; ++k) step(scaler, in, out);
    steady[f] = out.state.sdot;
  }
  EXPECT_NEAR(steady[0], 0.3, 1e-6);
  EXPECT_NEAR(steady[1], 0.15, 1e-6);
}

TEST(PathScalerFunctions, TrackingFactorStopBoundAndLowestCap) {
  EXPECT_EQ(scaling::tracking_factor(0.01, 0.05), 1.0);
  EXPECT_DOUBLE_EQ(scaling::tracking_factor(0.1, 0.05), 0.5);

  scaling::AccelerationBounds b;
  b.sddot_min = -2.0;
  EXPECT_EQ(scaling::stop_bound(b, 5.0), -2.0) << "the constraints' own when it allows slowing";
  b.sddot_min = 0.3;
  EXPECT_EQ(scaling::stop_bound(b, 5.0), -5.0) << "never forced to speed up";

  scaling::SpeedLimits speed;
  speed.sdot_flow = 0.8;
  speed.sdot_cylinder = 0.6;
  scaling::AccelerationBounds acc;
  acc.sdot_power = 0.7;
  acc.sdot_acceleration = 1e300;
  auto cap = scaling::lowest_speed_cap(1.0, 1.0, 1e300, speed, acc);
  EXPECT_EQ(cap.value, 0.6);
  EXPECT_EQ(cap.kind, scaling::ActiveLimit::kCylinderSpeed);
  cap = scaling::lowest_speed_cap(1.0, 1.0, 1e300, speed, acc, true);
  EXPECT_EQ(cap.kind, scaling::ActiveLimit::kSingularity) << "near a singular pose";
  cap = scaling::lowest_speed_cap(0.5, 1.0, 1e300, speed, acc);
  EXPECT_EQ(cap.value, 0.5);
  EXPECT_EQ(cap.kind, scaling::ActiveLimit::kNone) << "the operator's request";
  cap = scaling::lowest_speed_cap(1.0, 1.0, 0.2, speed, acc);
  EXPECT_EQ(cap.kind, scaling::ActiveLimit::kJointLimit);
}
