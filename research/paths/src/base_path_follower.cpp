#include "craneassist/paths/base_path_follower.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace craneassist::paths {
using namespace craneassist::scaling;  // the scaling room these paths are built on

double wrap_angle(double a) noexcept {
  const double two_pi = 2.0 * std::numbers::pi;
  a = std::fmod(a, two_pi);
  if (a <= -std::numbers::pi) a += two_pi;
  if (a > std::numbers::pi) a -= two_pi;
  return a;
}

BasePathFollower::BasePathFollower(const dynamics::MobileBaseModel& model,
                                   const CompositeBezierPath& path,
                                   const BaseFollowerConfig& config)
    : model_(model), path_(path), config_(config) {
  const OffsetPathCheck check = check_offset_path(path, config.tool_offset_m);
  if (!(check.min_v_prime_m > 0.0)) {
    std::ostringstream why;
    why << "the platform's path, " << config.tool_offset_m
        << " m beside the tool path, has a cusp near s = " << check.min_v_prime_s
        << " (the tool path turns tighter than the offset there)";
    throw std::invalid_argument(why.str());
  }
}

void BasePathFollower::reset(double s) noexcept {
  s_ = std::clamp(s, 0.0, 1.0);
}

void BasePathFollower::update(const BaseFollowerInput& in, BaseFollowerOutput& out) noexcept {
  OffsetReference& ref = out.reference;
  offset_reference(path_, config_.tool_offset_m, s_, ref);
  // Eq. 10: the configuration error in the path frame.
  const double c_phi = std::cos(ref.phi_rad), s_phi = std::sin(ref.phi_rad);
  const double dx = in.pose.x_m - ref.platform.x(), dy = in.pose.y_m - ref.platform.y();
  out.e_phi_rad = wrap_angle(in.pose.phi_rad - ref.phi_rad);
  out.e_x_m = c_phi * dx + s_phi * dy;
  out.e_y_m = -s_phi * dx + c_phi * dy;
  // Eq. 11.
  out.sigma_rad = std::asin(config_.k2 * out.e_y_m / (std::abs(out.e_y_m) + config_.epsilon_m));
  const double c = std::max(std::cos(out.sigma_rad) + config_.k1_1_m * out.e_x_m, kMinProgressGain);
  // Eq. 12 per unit forward speed, then the steering limit.
  const double kappa_wanted =
      ref.omega_prime_rad * c / ref.v_prime_m - config_.k3_1_m * (out.e_phi_rad + out.sigma_rad);
  const double kappa_max = dynamics::max_curvature_1_m(model_);
  out.curvature_1_m = std::clamp(kappa_wanted, -kappa_max, kappa_max);
  out.steering_limited = out.curvature_1_m != kappa_wanted;
  // Eqs. 14-15: the flow bound, and the motor speed bound where one is set.
  out.flow_budget_m3_s = model_.pump_max_flow_m3_s;
  if (arm_shares_pump_)
    out.flow_budget_m3_s = std::max(0.0, out.flow_budget_m3_s - in.arm_flow_m3_s);
  out.v_max_m_s = out.flow_budget_m3_s / dynamics::flow_per_speed_m2(model_, out.curvature_1_m);
  out.limit = BaseLimit::kFlow;
  if (model_.motor_speed_max_rad_s > 0.0) {
    const double v_motor = model_.motor_speed_max_rad_s /
                           dynamics::motor_speed_per_speed_1_m(model_, out.curvature_1_m);
    if (v_motor < out.v_max_m_s) {
      out.v_max_m_s = v_motor;
      out.limit = BaseLimit::kMotorSpeed;
    }
  }
  // Eq. 17-18.
  const double delta = std::clamp(in.tracking_factor, 0.0, 1.0);
  if (delta < 1.0) out.limit = BaseLimit::kTrackingError;
  out.finished = s_ >= 1.0;
  out.v_m_s = out.finished ? 0.0 : out.v_max_m_s * delta;
  if (out.finished) out.limit = BaseLimit::kEnd;
  out.omega_rad_s = out.curvature_1_m * out.v_m_s;
  out.sdot = out.v_m_s * c / ref.v_prime_m;
  s_ = std::min(1.0, s_ + out.sdot * config_.period_s);
  out.s = s_;
  dynamics::wheel_inverse_kinematics(model_, out.omega_rad_s, out.v_m_s, out.wheels);
}

}  // namespace craneassist::paths
