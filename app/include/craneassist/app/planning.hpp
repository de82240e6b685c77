// Glue between the offline planner and the files around it: a prescribed tip path sampled for
// the planner, and a plan written as a joint trajectory.
#pragma once

#include <string>

#include "craneassist/input/joint_trajectory.hpp"
#include "craneassist/planner/dp_planner.hpp"

namespace craneassist::app {

// The plan's joint positions, rates and accelerations at its stage times, with a summary of the
// plan (method, cost, totals) as comment lines.
input::JointTrajectory to_joint_trajectory(const planner::Plan& plan, const std::string& source);

}  // namespace craneassist::app
