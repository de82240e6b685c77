// `sim --input goal` (docs/mhsb.md, "The K70M: a goal for sim"): "move the tip to this point"
// energy-optimally. The point-to-point planner (planner/ptp_planner.hpp) plans the tip's path in
// the arm's vertical plane from where the tip is; the plan becomes a tip trajectory that
// input::GoalSource follows through the normal controller, so the controller's redundancy
// resolution, scaling, joint ends and stops apply as to a stick. The goal may change while the
// tip moves: at scheduled times (--goal-at) or typed on standard input; each change replans from
// the measured tip, on this planner thread, never on the control thread.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "craneassist/input/goal_source.hpp"
#include "craneassist/planner/ptp_planner.hpp"

namespace craneassist::cli {

// A goal (X, Z in the arm's plane, m) to take from t_s seconds after the run starts.
struct GoalAt {
  double t_s = 0.0;
  Eigen::Vector2d xz = Eigen::Vector2d::Zero();
};

// "X,Z" (at t = 0) and "T:X,Z" entries, in time order; throws CLI::ValidationError naming the
// option for malformed text, a negative or non-finite time, or two goals at one time.
std::vector<GoalAt> parse_goals(const std::string& goal, const std::vector<std::string>& goal_at);

// The plan as a tip trajectory in the crane frame, blended so that it starts at the measured tip
// and ends at the goal itself (the planner's path runs from node to node of its grid): the
// offsets at both ends are faded across the move with a smoothstep, their velocity added. The
// planner times a move by its cylinders' speed limits (quasi-statically, paper 001's assumption
// 2); where that asks for more tip speed than max_tip_speed_m_s or more tip acceleration than
// half of max_tip_acceleration_m_s2 (the controller's path acceleration bound: the other half is
// left for its corrections), the whole move is slowed uniformly (time stretched by k: speeds
// divided by k, accelerations by k^2), since the controller's scaling would cut it anyway and the
// tip would lag and overshoot.
struct TipLimits {
  double speed_m_s = 0.5;
  double acceleration_m_s2 = 1.0;
};
std::vector<input::TipSample> tip_trajectory(const planner::PlanarArm& arm,
                                             const planner::PtpPlan& plan,
                                             const Eigen::Vector3d& tip_now_m,
                                             const Eigen::Vector2d& goal_xz,
                                             const TipLimits& limits);

class GoalPlanner {
 public:
  // planner and source must outlive this object. read_stdin: also take goals typed as "X,Z"
  // lines on standard input.
  GoalPlanner(planner::PtpPlanner& planner, input::GoalSource& source, std::vector<GoalAt> goals,
              const planner::PtpWeights& weights, const TipLimits& limits, bool read_stdin);
  ~GoalPlanner();
  GoalPlanner(const GoalPlanner&) = delete;
  GoalPlanner& operator=(const GoalPlanner&) = delete;

  void start();
  void stop();  // joins the thread
  // Lines for the run's summary: goals planned, planning times, goals refused and why.
  std::vector<std::string> report() const;

 private:
  void run();
  void plan_to(const Eigen::Vector2d& goal, const Eigen::Vector3d& tip, double now_s,
               const char* origin);

  planner::PtpPlanner& planner_;
  input::GoalSource& source_;
  std::vector<GoalAt> goals_;
  planner::PtpWeights weights_;
  TipLimits limits_;
  bool read_stdin_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  mutable std::mutex mutex_;
  std::vector<std::string> report_;  // the first kMaxReportedGoals goals' lines
  long unlisted_ = 0;                // goals after those
  static constexpr std::size_t kMaxReportedGoals = 100;
  std::string stdin_buffer_;
  std::optional<double> start_s_;  // the loop clock at the first measured tip
};

}  // namespace craneassist::cli
