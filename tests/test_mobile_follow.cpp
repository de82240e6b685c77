// The crane on wheels follows the paper's tool path (offline/mobile_follow.hpp, docs/mobile.md)
// in both of the paper's cases: the drive motors' flow never above Q_max, and with the
// tool-error scaling the platform waits for the arm, so the tool error is smaller and the path
// takes longer.
#include <gtest/gtest.h>

#include "craneassist/config/base_config.hpp"
#include "craneassist/input/tool_path_file.hpp"
#include "craneassist/offline/mobile_follow.hpp"

namespace {

using namespace craneassist;

struct Cases {
  offline::FollowResult flow_only, error_scaling;
};

const Cases& cases() {
  static const Cases c = [] {
    const config::CraneConfig crane = config::default_crane_config();
    const config::BaseConfig base = config::default_base_config();
    const input::ToolPathFile file = input::load_tool_path(std::string(CRANEASSIST_SOURCE_DIR) +
                                                           "/examples/paths/mobile_s_curve.csv");
    const scaling::CompositeBezierPath path(file.via_m);
    offline::FollowOptions options;
    Cases out;
    options.error_scaling = false;
    out.flow_only = offline::run_follow(crane, base, path, options);
    options.error_scaling = true;
    out.error_scaling = offline::run_follow(crane, base, path, options);
    return out;
  }();
  return c;
}

}  // namespace

TEST(MobileFollow, BothCasesFinishWithinTheFlowBound) {
  for (const auto* r : {&cases().flow_only, &cases().error_scaling}) {
    const offline::FollowSummary& s = r->summary;
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
  const offline::FollowSummary& without = cases().flow_only.summary;
  const offline::FollowSummary& with = cases().error_scaling.summary;
  EXPECT_LT(with.rms_tool_error_m, without.rms_tool_error_m);
  EXPECT_LT(with.peak_tool_error_m, without.peak_tool_error_m);
  EXPECT_GT(with.completion_time_s, without.completion_time_s);
  // The slew (the paper's base rotation joint) moves less.
  EXPECT_LT(with.peak_slew_rate_rad_s, without.peak_slew_rate_rad_s);
}

TEST(MobileFollow, ErrorScalingCorrectsTheStartBeforeThePlatformAdvances) {
  // Until the start's tool error has come below 0.2 m the platform has hardly moved along its
  // path with the scaling, and has without it.
  auto progress_when_settled = [](const offline::FollowResult& r) {
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
