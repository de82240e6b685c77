#include "craneassist/control/polytope_probe.hpp"

#include "craneassist/dynamics/cylinders.hpp"

namespace craneassist::control {

PolytopeProbe::PolytopeProbe(const config::CraneConfig& config, ScalingMode mode)
    : model_(config.model),
      // The full scaling keeps the reserve on both the pump flow and the cylinder speeds
      // (path_speed_limits), the flow-only prescaling on the flow only (flow_prescale).
      settings_{
          .flow_reserve = config.control.flow_reserve,
          .cylinder_speed_reserve = mode == ScalingMode::kFull ? config.control.flow_reserve : 0.0},
      polytope_(config.model.dof(), 3) {
  arms_.setZero(model_.dof());
}

void PolytopeProbe::update(const JointVector& q, const Eigen::Vector3d& command,
                           const JointVector& motion, double tip_speed,
                           ControllerOutput& out) noexcept {
  dynamics::cylinder_arms(model_, q, arms_);
  dynamics::tip_jacobian(model_, kin_, q, jacobian_);
  dynamics::joint_velocity_set(model_, q, arms_, settings_, set_);
  polytope_.update(set_, jacobian_);
  polytope_.build_hull();
  out.polytope_dim = polytope_.dimension();
  out.polytope_volume_m3_s3 = polytope_.volume();
  out.polytope_area_m2_s2 = polytope_.area();
  const double stick = command.norm();
  if (stick > 0.0) stick_direction_ = command / stick;
  out.avail_speed_m_s = polytope_.max_speed(stick_direction_);
  // Along the joint motion the cycle chose; none (a singular pose where the resolution gives up
  // on u, a released stick, a stale input) has no speed along it.
  out.avail_speed_resolved_m_s = 0.0;
  if (tip_speed > 0.0 && !motion.isZero(0.0)) {
    out.avail_speed_resolved_m_s = dynamics::speed_along(set_, motion) * tip_speed;
  }
}

}  // namespace craneassist::control
