// Flow-bounded path following of the wheeled base ("Flow-limited path-following control of a
// double Ackermann steered hydraulic mobile manipulator", eqs. 6-18; docs/mobile.md): the
// path-velocity decomposition of the platform's planar path, the approach angle sigma(e_y), the
// control law and the path progress, with the forward speed at the most the drive pump allows.
//
// Each cycle, at the reference s:
//   errors (eq. 10)  e_phi = phi - phi_d,  e_x, e_y = the position error in the path frame
//                    (e_y > 0: the platform is left of its path)
//   sigma (eq. 11)   sigma = asin(k2 e_y / (|e_y| + epsilon))
//   c                = cos sigma + k1 e_x (held >= kMinProgressGain)
//   curvature (eq. 12 divided by v_d)
//                    kappa = omega' c / v' - k3 (e_phi + sigma), clamped to the steering limit
//   v_max (eqs. 14-15) the sum of the hub-motor flows at (v, kappa v) is Q(v) = v F(kappa), so
//                    v_max = Q_budget / F(kappa); with a motor speed limit also
//                    n_max / N(kappa); Q_budget = Q_max less the arm's flow when it shares the
//                    pump
//   command (eq. 17) v_d = v_max delta(|e|),  omega_d = kappa v_d
//   progress (eq. 18) sdot = v_d c / v'
// The paper writes the heading term k3 (e_phi - sigma) / c sdot with k3 per unit path
// parameter; here k3 is per metre (the term is -k3 (e_phi + sigma) v_d), so a gain does not
// depend on the path's length, and the sign is the one that steers towards the path with e_y
// measured to the left.
//
// At the end of the path (s = 1) the platform stops. update() allocates nothing, throws nothing.
#pragma once

#include "craneassist/dynamics/mobile_base.hpp"
#include "craneassist/paths/planar_path.hpp"
#include "craneassist/scaling/base_drive.hpp"

namespace craneassist::paths {

using scaling::BaseLimit;

struct BaseFollowerConfig {
  double k1_1_m = 0.5;
  double k2 = 0.9;
  double k3_1_m = 1.0;
  double epsilon_m = 0.5;
  double tool_offset_m = 4.5;  // the tool path lies this far left of the platform's
  double period_s = 0.01;
};

struct BaseFollowerInput {
  dynamics::BasePose pose;       // measured
  double tracking_factor = 1.0;  // delta(|e|) of the tool error, (0, 1]
  double arm_flow_m3_s = 0.0;    // counted against the drive pump when it feeds the arm too
};

struct BaseFollowerOutput {
  double s = 0.0, sdot = 0.0;  // after this cycle
  OffsetReference reference;   // at the s the errors were taken
  double e_phi_rad = 0.0, e_x_m = 0.0, e_y_m = 0.0, sigma_rad = 0.0;
  double curvature_1_m = 0.0;  // commanded, after the steering limit
  bool steering_limited = false;
  double v_max_m_s = 0.0;                 // flow (and motor speed) bound
  double v_m_s = 0.0, omega_rad_s = 0.0;  // the command (eq. 17)
  double flow_budget_m3_s = 0.0;
  dynamics::WheelState wheels;  // of the command
  BaseLimit limit = BaseLimit::kFlow;
  bool finished = false;
};

class BasePathFollower {
 public:
  // The model and path are kept by reference. Throws std::invalid_argument when the offset path
  // has a cusp (v' <= 0) anywhere.
  BasePathFollower(const dynamics::MobileBaseModel& model, const CompositeBezierPath& path,
                   const BaseFollowerConfig& config);

  void reset(double s = 0.0) noexcept;
  double s() const noexcept { return s_; }
  const BaseFollowerConfig& config() const noexcept { return config_; }
  // The flow budget of the drive motors: Q_max, less the arm's flow when arm_shares_pump.
  void set_arm_shares_pump(bool shares) noexcept { arm_shares_pump_ = shares; }

  void update(const BaseFollowerInput& in, BaseFollowerOutput& out) noexcept;

  static constexpr double kMinProgressGain = 0.05;

 private:
  const dynamics::MobileBaseModel& model_;
  const CompositeBezierPath& path_;
  BaseFollowerConfig config_;
  bool arm_shares_pump_ = false;
  double s_ = 0.0;
};

// Wraps an angle to (-pi, pi].
double wrap_angle(double a) noexcept;

}  // namespace craneassist::paths
