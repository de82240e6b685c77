// One cycle's measurements and log row, shared by the replay loop and the live loop so that the
// same command sequence gives the same row in both (record and replay rely on it).
#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>

#include "craneassist/control/controller.hpp"
#include "craneassist/control/csv_log.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/urdf.hpp"

namespace craneassist::control {

class LogRowBuilder {
 public:
  explicit LogRowBuilder(const dynamics::CraneModel& model);

  // The measured tip position and velocity (crane frame; zero when the state is invalid), the
  // cylinder positions and velocities, and the hanger joints' angles (their rates from the last
  // measurement). Allocation-free.
  void measure(const valves::MachineState& state) noexcept;
  const Eigen::Vector3d& tip() const noexcept { return tip_; }
  const Eigen::Vector3d& tip_velocity() const noexcept { return tip_v_; }

  // Every field of the row from this cycle (after measure()); status, stop_reason,
  // input_source and deadman are left to the caller.
  void fill(LogRow& row, double t, const Eigen::Vector3d& cmd, const ControllerOutput& out,
            const valves::MachineState& state) const noexcept;

 private:
  const dynamics::CraneModel& model_;
  dynamics::KinematicsData kin_;
  dynamics::TaskJacobian jac_;
  dynamics::JointVector cyl_pos_, cyl_arm_;
  Eigen::Vector3d tip_ = Eigen::Vector3d::Zero(), tip_v_ = Eigen::Vector3d::Zero();
  dynamics::HangerAxes hanger_axes_;
  std::array<double, 2> hanger_{}, hanger_rate_{};
  double hanger_t_s_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace craneassist::control
