// "Move the tip to this point": a command source that follows a planned tip trajectory
// (docs/mhsb.md, "The K70M: a goal for sim"). A planner outside the control thread publishes a
// plan, a time-stamped sequence of tip positions, whenever the goal changes; each cycle this input
// samples the newest plan at machine time and commands
//     v = v_ref(t) + k (p_ref(t) - tip),   the feedback part at most feedback_speed_cap_m_s,
// as a stick's source would, with the deadman held: through the input monitor and the normal
// controller, so scaling, joint ends and every stop apply as to a stick. At the plan's end it
// keeps pulling the tip to the goal until it is within goal_tolerance_m, then releases the
// deadman (state() "goal reached": the controller's jerk-limited stop, valves neutral); before any
// plan it has no data ("no goal"). Times are the loop's clock (begin_cycle's now_s: steady_clock
// seconds when paced, machine time otherwise).
//
// Threads: publish() on one producer thread, begin_cycle()/poll() on the control thread. The
// handoff is a triple buffer (three preallocated plans, one atomic index exchange each way): the
// control thread never blocks, never allocates and always sees a whole plan. The measured tip goes
// the other way through a sequence lock (last_tip()), for the producer to plan from.
#pragma once

#include <Eigen/Core>
#include <array>
#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "craneassist/input/command_source.hpp"
#include "craneassist/input/triple_buffer.hpp"

namespace craneassist::input {

struct TipSample {
  double t_s = 0.0;                                 // from the plan's start
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();    // crane frame
  Eigen::Vector3d v_m_s = Eigen::Vector3d::Zero();  // crane frame
};

struct GoalSourceSettings {
  std::size_t capacity = 8192;          // samples per plan
  double position_gain_1_s = 2.0;       // k
  double feedback_speed_cap_m_s = 0.3;  // |k e| at most this
  double goal_tolerance_m = 0.02;       // within this of the goal at the plan's end: reached
  // How long the input monitor needs the deadman held before a command passes
  // (InputMonitorSettings::deadman_hold_s): a plan that starts from rest starts after it.
  double arming_s = 0.3;
};

class GoalSource final : public CommandSource {
 public:
  explicit GoalSource(const GoalSourceSettings& settings);  // allocates the three plans

  // Producer thread. samples: times strictly increasing from 0, at most capacity (more: false,
  // nothing published); start_t_s: the loop-clock time of sample 0. Replaces any earlier plan.
  bool publish(std::span<const TipSample> samples, double start_t_s);
  // Producer thread: the newest measured tip and its loop-clock time (false before any cycle,
  // or while the tip measurement is invalid).
  bool last_tip(Eigen::Vector3d& tip_m, double& t_s) const noexcept;
  // Producer thread: how many plans the control thread has taken up.
  std::uint64_t plans_taken() const noexcept { return taken_.load(std::memory_order_acquire); }

  void begin_cycle(double now_s, const Eigen::Vector3d& tip_m) noexcept override;
  SourceState poll(OperatorCommand& out) noexcept override;
  const char* name() const noexcept override { return "goal"; }

  // Control thread (or after the run): the plan in use and where on it the last cycle was.
  bool has_plan() const noexcept { return plans_.front().count > 0; }
  bool reached() const noexcept { return reached_; }
  // "no goal", "arming" (before a move from rest: one cycle with the deadman released, as the input
  // monitor arms on a press, then arming_s with it held and no motion), "following", "goal
  // reached", "no tip measurement".
  const char* state() const noexcept { return state_; }
  const Eigen::Vector3d& reference() const noexcept { return reference_; }

 private:
  struct Plan {
    std::vector<TipSample> samples;  // capacity preallocated
    std::size_t count = 0;
    double start_t_s = 0.0;
  };
  void sample(double tau_s, Eigen::Vector3d& p, Eigen::Vector3d& v) noexcept;

  GoalSourceSettings settings_;
  double now_s_ = 0.0;
  Eigen::Vector3d tip_m_ = Eigen::Vector3d::Zero();
  const char* state_ = "no goal";
  bool primed_ = false;  // the deadman was reported released since the last stop
  double primed_at_s_ = 0.0;
  bool waiting_ = false;      // the plan's clock waits for the arming to end
  TripleBuffer<Plan> plans_;  // the producer writes the back plan, the loop follows the front
  std::size_t cursor_ = 0;
  bool reached_ = false;
  Eigen::Vector3d reference_ = Eigen::Vector3d::Zero();
  std::atomic<std::uint64_t> taken_{0};
  // Sequence lock on the measured tip: odd while being written.
  std::atomic<std::uint64_t> tip_seq_{0};
  std::array<std::atomic<double>, 4> tip_{};  // x, y, z, t
};

}  // namespace craneassist::input
