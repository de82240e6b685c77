// The simulated wheeled base and the crane standing on it (docs/mobile.md): the kinematic
// simulation of "Flow-limited path-following control of a double Ackermann steered hydraulic
// mobile manipulator" (section IV): the base's velocity inputs (forward speed, yaw rate) lagged
// by a first-order transfer function, the pose integrated by the bicycle model (eq. 1), the
// hub-motor speeds and flows of the motion that results (eqs. 2-5). The crane is the ODE crane
// of SimBackend on the platform: its joints, valves and pump as on a fixed base, its tip carried
// into the world by the platform's pose. The platform's own accelerations are not fed into the
// crane's rigid-body dynamics (the paper's simulation is kinematic; at the base's 0.3 m/s and
// 0.1 rad/s they are a few hundredths of g).
//
// step() allocates nothing and throws nothing.
#pragma once

#include "craneassist/dynamics/mobile_base.hpp"

namespace craneassist::sim_backend {

struct MobileBaseState {
  double t_s = 0.0;
  dynamics::BasePose pose;
  dynamics::BaseVelocity velocity;  // after the lag
  dynamics::WheelState wheels;      // of that motion: steering, motor speeds, flows
};

class MobileBaseSim {
 public:
  MobileBaseSim(const dynamics::MobileBaseModel& model, const dynamics::BasePose& initial);

  // The velocity command for the coming steps.
  void command(const dynamics::BaseVelocity& command) noexcept { command_ = command; }
  // Lets dt pass: the lag, then the arc with the lagged velocities, in sub-steps of at most
  // 1 ms.
  void advance(double dt_s) noexcept;
  const MobileBaseState& state() const noexcept { return state_; }
  const dynamics::MobileBaseModel& model() const noexcept { return model_; }

 private:
  dynamics::MobileBaseModel model_;
  dynamics::BaseVelocity command_;
  MobileBaseState state_;
};

}  // namespace craneassist::sim_backend
