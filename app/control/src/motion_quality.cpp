#include "craneassist/control/motion_quality.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace craneassist::control {
namespace {

constexpr double kParallel = 1e-9;  // |u x line| below this: on the line

}  // namespace

void MotionQuality::add(double t_s, const Eigen::Vector3d& command, const Eigen::Vector3d& tip_m,
                        const Eigen::Vector3d& tip_velocity_m_s) {
  const bool valid = command.allFinite();
  const double speed_cmd = valid ? command.norm() : 0.0;

  // The line of the commands.
  if (speed_cmd > 0.0) {
    const Eigen::Vector3d u = command / speed_cmd;
    if (!has_line_) {
      has_line_ = true;
      result_.one_line = true;
      result_.line = u;
    } else if (result_.one_line && u.cross(result_.line).norm() > kParallel) {
      result_.one_line = false;
      result_.lateral_peak_m_s = result_.lateral_peak_cycle_m_s = 0.0;
    }
  }

  // Tip velocity over the window (positions kWindowCycles cycles apart).
  tips_[static_cast<std::size_t>(cycles_ % (kWindowCycles + 1))] = tip_m;
  const bool window_full = cycles_ >= kWindowCycles;
  Eigen::Vector3d window_velocity = Eigen::Vector3d::Zero();
  if (window_full) {
    const auto& oldest = tips_[static_cast<std::size_t>((cycles_ + 1) % (kWindowCycles + 1))];
    window_velocity = (tip_m - oldest) / (kWindowCycles * period_s_);
  }
  ++cycles_;

  // Lateral speed normal to the line; the window covers the whole run, including before the
  // first command (where any motion is lateral to nothing yet: counted once the line is known).
  if (result_.one_line && has_line_) {
    const Eigen::Vector3d& line = result_.line;
    const double cycle = (tip_velocity_m_s - tip_velocity_m_s.dot(line) * line).norm();
    result_.lateral_peak_cycle_m_s = std::max(result_.lateral_peak_cycle_m_s, cycle);
    if (window_full) {
      const double lateral = (window_velocity - window_velocity.dot(line) * line).norm();
      if (lateral > result_.lateral_peak_m_s) {
        result_.lateral_peak_m_s = lateral;
        result_.lateral_peak_t_s = t_s;
      }
    }
  }

  // Stall events, per stick position.
  if (!(valid && command == stick_)) {
    stick_ = valid ? command : Eigen::Vector3d::Zero();
    reached_ = dipped_ = false;
  }
  if (speed_cmd > 0.0 && window_full) {
    const double share = window_velocity.dot(command) / (speed_cmd * speed_cmd);
    if (share >= kReachedShare) reached_ = true;
    if (reached_ && share < kStallShare) dipped_ = true;
    if (dipped_ && share >= kRecoveredShare) {
      ++result_.stall_events;
      dipped_ = false;
      reached_ = share >= kReachedShare;
    }
  }
}

}  // namespace craneassist::control
