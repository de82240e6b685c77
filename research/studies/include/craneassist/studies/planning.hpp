// Glue between the offline planner and the files around it: a prescribed tip path sampled for
// the planner, the paper's choice of start configuration, the planning methods by name, and a
// plan written as a joint trajectory.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "craneassist/dynamics/enum_names.hpp"
#include "craneassist/input/joint_trajectory.hpp"
#include "craneassist/input/prescribed_path.hpp"
#include "craneassist/planner/dp_planner.hpp"

namespace craneassist::studies {

// The path at t_k = start + k dt, k = 0..N, N = ceil(duration / dt) (the last sample at the end).
planner::TipSamples sample_path(const input::PrescribedPath& path, double dt_s);

// Paper 000 section 6 starts every path from two configurations: the shortest feasible
// extension cylinder length, and the middle of the feasible range.
enum class StartExtension { kShortest, kMiddle };
inline constexpr std::array kStartExtensions{StartExtension::kShortest, StartExtension::kMiddle};
const char* to_string(StartExtension start);  // "shortest", "middle"
inline std::optional<StartExtension> parse_start_extension(std::string_view text) {
  return parse_name(kStartExtensions, text);
}

// The extension cylinder length at stage 0; throws std::runtime_error when no extension keeps
// every joint within its range at the path's start.
double start_extension(const planner::StageModel& stages, StartExtension start);

// The planning methods: "dp", then the online resolutions' names (pinv-joint, pinv-actuator,
// min-flow, min-ls-power).
std::vector<std::string> plan_methods();
bool is_plan_method(std::string_view method);

// Plans with the method from extension cylinder length c_start.
planner::Plan make_plan(const planner::StageModel& stages, std::string_view method, double c_start,
                        const planner::DpOptions& dp_options);

// The plan's joint positions, rates and accelerations at its stage times, with a summary of the
// plan (method, cost, totals) as comment lines.
input::JointTrajectory to_joint_trajectory(const planner::Plan& plan, const std::string& source);

}  // namespace craneassist::studies
