// The operator's drive of the wheeled base (sim --base, docs/mobile.md#live): one stick gives
// forward speed and curvature as fractions of their limits, bounded the way the path follower
// bounds its own (base_path_follower.hpp; "Flow-limited path-following control of a double
// Ackermann steered hydraulic mobile manipulator", eqs. 14-15):
//
//   curvature  kappa = curvature_fraction * kappa_max         (the steering limit)
//   v_max            = Q_budget / F(kappa)                    (the hub motors' summed flow)
//                      and n_max / N(kappa) with a motor speed limit
//   command    v = speed_fraction * v_max,  omega = kappa v
//
// so the summed motor flow of the command is at most Q_budget, and at a constant curvature the
// stick's travel is the share of the pump the drive takes. Allocation-free, exception-free.
#pragma once

#include "craneassist/dynamics/mobile_base.hpp"

namespace craneassist::scaling {

// What set the forward speed (here and in the studies' path follower).
enum class BaseLimit { kFlow, kMotorSpeed, kTrackingError, kEnd };
const char* to_string(BaseLimit limit);  // "flow", "motor_speed", "tracking_error", "end"

struct BaseDriveOutput {
  double v_m_s = 0.0, omega_rad_s = 0.0;  // the command
  double curvature_1_m = 0.0;
  double v_max_m_s = 0.0;              // the bound at that curvature
  BaseLimit limit = BaseLimit::kFlow;  // kFlow or kMotorSpeed
};

// Fractions outside [-1, 1] are clamped; a non-finite one gives a standstill.
void flow_bounded_drive(const dynamics::MobileBaseModel& model, double speed_fraction,
                        double curvature_fraction, double flow_budget_m3_s,
                        BaseDriveOutput& out) noexcept;

}  // namespace craneassist::scaling
