#include "craneassist/app/planning.hpp"

#include <cstdio>

namespace craneassist::app {

input::JointTrajectory to_joint_trajectory(const planner::Plan& plan, const std::string& source) {
  const int n = plan.points.empty() ? 0 : static_cast<int>(plan.points.front().q.size());
  input::JointTrajectory traj(n);
  char line[256];
  traj.comments.push_back("craneassist plan: " + source);
  std::snprintf(line, sizeof line, "method %s, cost %s: total %.6g, penalties %.6g (%d stages)",
                plan.method.c_str(), planner::to_string(plan.cost_function), plan.total_cost,
                plan.total_penalty, plan.penalised_stages);
  traj.comments.emplace_back(line);
  traj.comments.emplace_back("t [s], joint positions q [rad, m], rates qdot, accelerations qddot");
  for (const auto& p : plan.points) {
    traj.append(p.t_s, Eigen::VectorXd(p.q), Eigen::VectorXd(p.qdot), Eigen::VectorXd(p.qddot));
  }
  return traj;
}

}  // namespace craneassist::app
