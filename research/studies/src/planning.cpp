#include "craneassist/studies/planning.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "craneassist/control/control_loop.hpp"

namespace craneassist::studies {

planner::TipSamples sample_path(const input::PrescribedPath& path, double dt_s) {
  if (!(dt_s > 0.0)) throw std::invalid_argument("the planner's time step must be positive");
  planner::TipSamples s;
  s.dt_s = dt_s;
  const long n =
      std::max(1L, control::run_cycles(std::ceil(path.duration_s() / dt_s - 1e-9), "the path"));
  for (long k = 0; k <= n; ++k) {
    const auto point = path.at(path.start_time_s() + static_cast<double>(k) * dt_s);
    s.p_m.push_back(point.p_m);
    s.v_m_s.push_back(point.v_m_s);
    s.a_m_s2.push_back(point.a_m_s2);
  }
  return s;
}

const char* to_string(StartExtension start) {
  return start == StartExtension::kShortest ? "shortest" : "middle";
}

double start_extension(const planner::StageModel& stages, StartExtension start) {
  double lo = 0.0, hi = 0.0;
  if (!planner::feasible_extension_range(stages, 0, lo, hi)) {
    throw std::runtime_error(
        "no extension reaches the path's start with every joint within its range");
  }
  return start == StartExtension::kShortest ? lo : 0.5 * (lo + hi);
}

std::vector<std::string> plan_methods() {
  std::vector<std::string> methods = names_of(dynamics::kResolutions);
  methods.emplace(methods.begin(), "dp");
  return methods;
}

bool is_plan_method(std::string_view method) {
  return method == "dp" || dynamics::parse_resolution(method);
}

planner::Plan make_plan(const planner::StageModel& stages, std::string_view method, double c_start,
                        const planner::DpOptions& dp_options) {
  if (method == "dp") return planner::plan_dp(stages, c_start, dp_options);
  const auto r = dynamics::parse_resolution(method);
  if (!r) throw std::invalid_argument("unknown planning method '" + std::string(method) + "'");
  return planner::plan_online(stages, *r, c_start);
}

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

}  // namespace craneassist::studies
