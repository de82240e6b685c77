// What an operator feels of a run, measured on the machine (docs/scaling.md#operator-feel):
//
//  - stall events: with the stick unchanged, the measured tip speed along the command falls
//    below 30 % of the commanded speed after having reached 90 % of it, and recovers above 70 %
//    (a slow-down for no reason the operator can see; reaching the edge of the workspace and
//    stopping there is not one).
//  - lateral speed: on a run whose commands all lie on one line through zero (pushes and pure
//    reversals), the largest measured tip speed normal to that line. Measured over 50 ms (five
//    control cycles) of tip positions, as a tip speed an operator sees; the largest single-cycle
//    value, which also holds the millimetre bounces of a section closing, is kept beside it.
//
// Speeds along the stick for the stall count use the same 50 ms window. No allocation per cycle.
#pragma once

#include <Eigen/Core>
#include <array>

namespace craneassist::control {

struct MotionQualityResult {
  int stall_events = 0;
  bool one_line = false;  // every non-zero, valid command on one line through zero
  Eigen::Vector3d line = Eigen::Vector3d::Zero();  // its unit direction (one_line)
  double lateral_peak_m_s = 0.0;                   // over 50 ms (one_line)
  double lateral_peak_cycle_m_s = 0.0;             // single cycle (one_line)
  double lateral_peak_t_s = 0.0;                   // when the 50 ms peak happened
};

class MotionQuality {
 public:
  static constexpr int kWindowCycles = 5;
  static constexpr double kReachedShare = 0.9, kStallShare = 0.3, kRecoveredShare = 0.7;

  explicit MotionQuality(double period_s) : period_s_(period_s) {}

  // One control cycle: the command (non-finite: no valid input), the measured tip position and
  // velocity (crane frame).
  void add(double t_s, const Eigen::Vector3d& command, const Eigen::Vector3d& tip_m,
           const Eigen::Vector3d& tip_velocity_m_s);

  const MotionQualityResult& result() const { return result_; }

 private:
  double period_s_;
  MotionQualityResult result_;
  bool has_line_ = false;
  // Tip positions of the last kWindowCycles + 1 cycles, and the lateral peaks measured against
  // the line known so far (reset when a command off the line appears).
  std::array<Eigen::Vector3d, kWindowCycles + 1> tips_{};
  long cycles_ = 0;
  // Stall detection for the present stick position.
  Eigen::Vector3d stick_ = Eigen::Vector3d::Zero();
  bool reached_ = false, dipped_ = false;
};

}  // namespace craneassist::control
