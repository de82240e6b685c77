// The crane on wheels follows the paper's tool path (offline/mobile_follow.hpp, docs/mobile.md)
// in both of the paper's cases: the drive motors' flow never above Q_max, and with the
// tool-error scaling the platform waits for the arm, so the tool error is smaller and the path
// takes longer. With the crane and the drive on one pump (BaseConfig::shared_with_crane) the
// motors and the crane together never above Q_max, the arm starves in case 1 and the error
// scaling frees flow for it in case 2.
#include <gtest/gtest.h>

#include <algorithm>

#include "craneassist/config/base_config.hpp"
#include "craneassist/input/tool_path_file.hpp"
#include "craneassist/studies/mobile_follow.hpp"

namespace {

using namespace craneassist;

struct Cases {
  studies::FollowResult flow_only, error_scaling;
};

Cases run_cases(bool shared_pump) {
  const config::CraneConfig crane = config::default_crane_config();
  config::BaseConfig base = config::default_base_config();
  base.shared_with_crane = shared_pump;
  const input::ToolPathFile file = input::load_tool_path(std::string(CRANEASSIST_SOURCE_DIR) +
                                                         "/examples/paths/mobile_s_curve.csv");
  const paths::CompositeBezierPath path(file.via_m);
  studies::FollowOptions options;
  Cases out;
  options.error_scaling = false;
  out.flow_only = studies::run_follow(crane, base, path, options);
  options.error_scaling = true;
  out.error_scaling = studies::run_follow(crane, base, path, options);
  return out;
}

const Cases& shared_cases() {
  static const Cases c = run_cases(true);
  return c;
}

const Cases& cases() {
  static const Cases c = run_cases(false);
  return c;
}

}  // namespace

TEST(MobileFollow, BothCasesFinishWithinTheFlowBound) {
  for (const auto* r : {&cases().flow_only, &cases().error_scaling}) {
    const studies::FollowSummary& s = r->summary;
    EXPECT_GT(s.completion_time_s, 0.0);
    EXPECT_LE(s.peak_flow_ratio, 1.0 + 1e-9);
    EXPECT_LE(s.peak_commanded_flow_ratio, 1.0 + 1e-9);
    EXPECT_GT(s.peak_flow_ratio, 0.99);  // the bound sets the speed
    EXPECT_LT(s.final_platform_error_m, 0.2);
    for (const auto& row : r->rows) {
      ASSERT_LE(row.flow_sum, row.flow_max * (1.0 + 1e-9)) << "t = " << row.t;
    }
  }
}

TEST(MobileFollow, ErrorScalingGivesSmallerToolErrorsAndTakesLonger) {
  const studies::FollowSummary& without = cases().flow_only.summary;
  const studies::FollowSummary& with = cases().error_scaling.summary;
  EXPECT_LT(with.rms_tool_error_m, without.rms_tool_error_m);
  EXPECT_LT(with.peak_tool_error_m, without.peak_tool_error_m);
  EXPECT_GT(with.completion_time_s, without.completion_time_s);
  // The slew (the paper's base rotation joint) moves less.
  EXPECT_LT(with.peak_slew_rate_rad_s, without.peak_slew_rate_rad_s);
}

TEST(MobileFollow, ErrorScalingCorrectsTheStartBeforeThePlatformAdvances) {
  // Until the start's tool error has come below 0.2 m the platform has hardly moved along its
  // path with the scaling, and has without it.
  auto progress_when_settled = [](const studies::FollowResult& r) {
    for (const auto& row : r.rows) {
      if (row.tool_error < 0.2) return row.s * r.summary.path_length_m;
    }
    return -1.0;
  };
  const double with = progress_when_settled(cases().error_scaling);
  const double without = progress_when_settled(cases().flow_only);
  ASSERT_GE(with, 0.0);
  ASSERT_GE(without, 0.0);
  EXPECT_LT(with, 0.1);
  EXPECT_GT(without, 2.0 * with);
}

TEST(MobileFollowSharedPump, MotorsAndCraneTogetherNeverAboveQmax) {
  const double q_max = config::default_base_config().model.pump_max_flow_m3_s;
  for (const auto* r : {&shared_cases().flow_only, &shared_cases().error_scaling}) {
    EXPECT_GT(r->summary.completion_time_s, 0.0);
    EXPECT_LE(r->summary.peak_flow_ratio, 1.0 + 1e-9);
    double peak_arm = 0.0;
    for (const auto& row : r->rows) {
      ASSERT_LE(row.flow_sum + row.arm_flow, q_max * (1.0 + 1e-9)) << "t = " << row.t;
      ASSERT_LE(row.arm_flow_max, q_max - row.flow_sum + 1e-12) << "t = " << row.t;
      peak_arm = std::max(peak_arm, row.arm_flow);
    }
    EXPECT_GT(peak_arm, 0.0);  // the crane does get flow: the pump is shared, not taken
  }
}

TEST(MobileFollowSharedPump, CaseOneStarvesTheArmAndErrorScalingFreesFlowForIt) {
  const studies::FollowSummary& without = shared_cases().flow_only.summary;
  const studies::FollowSummary& with = shared_cases().error_scaling.summary;
  // Measured (docs/mobile.md): RMS 0.917 m without the scaling, 0.158 m with it; peak 2.40 m
  // and 1.58 m (the start). The margin asked here is a factor 4 on the RMS.
  EXPECT_LT(4.0 * with.rms_tool_error_m, without.rms_tool_error_m);
  EXPECT_LT(with.peak_tool_error_m, without.peak_tool_error_m);
  EXPECT_GT(with.completion_time_s, without.completion_time_s);
  // Case 1: the drive takes the whole pump at full speed and the arm cannot follow the height
  // wave (1 m amplitude): the error stays large after the start.
  EXPECT_GT(without.rms_tool_error_settled_m, 0.5);
  // Case 2: the platform slows until the arm has the flow it needs: after the start the error
  // stays within a few e_ok.
  ASSERT_GE(with.settled_at_s, 0.0);
  EXPECT_LT(with.peak_tool_error_settled_m, 0.2);
  // And the shared pump costs case 2 time against the crane on its own pump.
  EXPECT_GT(with.completion_time_s, cases().error_scaling.summary.completion_time_s);
}
