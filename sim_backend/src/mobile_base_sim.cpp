#include "craneassist/sim_backend/mobile_base_sim.hpp"

#include <algorithm>
#include <cmath>

namespace craneassist::sim_backend {

MobileBaseSim::MobileBaseSim(const dynamics::MobileBaseModel& model,
                             const dynamics::BasePose& initial)
    : model_(model) {
  state_.pose = initial;
  dynamics::wheel_inverse_kinematics(model_, 0.0, 0.0, state_.wheels);
}

void MobileBaseSim::advance(double dt_s) noexcept {
  if (!(dt_s > 0.0)) return;
  const int steps = std::max(1, static_cast<int>(std::ceil(dt_s / 1e-3 - 1e-9)));
  const double h = dt_s / steps;
  for (int k = 0; k < steps; ++k) {
    const dynamics::BaseVelocity before = state_.velocity;
    state_.velocity = dynamics::lag_velocity(model_, state_.velocity, command_, h);
    // The arc with the step's mean velocity (trapezoid).
    state_.pose =
        dynamics::integrate_pose(state_.pose, 0.5 * (before.v_m_s + state_.velocity.v_m_s),
                                 0.5 * (before.omega_rad_s + state_.velocity.omega_rad_s), h);
  }
  state_.t_s += dt_s;
  dynamics::wheel_inverse_kinematics(model_, state_.velocity.omega_rad_s, state_.velocity.v_m_s,
                                     state_.wheels);
}

}  // namespace craneassist::sim_backend
