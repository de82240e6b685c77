#include "craneassist/scaling/flow_prescaling.hpp"

#include <cmath>

#include "craneassist/dynamics/cylinders.hpp"

namespace craneassist::scaling {

const char* to_string(ActiveLimit limit) {
  switch (limit) {
    case ActiveLimit::kNone:
      return "none";
    case ActiveLimit::kFlow:
      return "flow";
    case ActiveLimit::kCylinderSpeed:
      return "cylinder_speed";
    case ActiveLimit::kPower:
      return "power";
    case ActiveLimit::kTrackingError:
      return "tracking_error";
    case ActiveLimit::kJointLimit:
      return "joint_limit";
    case ActiveLimit::kCylinderAcceleration:
      return "cylinder_acceleration";
    case ActiveLimit::kStaleInput:
      return "stale_input";
    case ActiveLimit::kSingularity:
      return "singularity";
    case ActiveLimit::kPressure:
      return "pressure";
    case ActiveLimit::kOverload:
      return "overload";
    case ActiveLimit::kDynamicsFailed:
      return "dynamics_failed";
  }
  return "?";
}

void flow_prescale(const dynamics::CraneModel& model, const dynamics::JointVector& dc_dq,
                   const dynamics::JointVector& qdot, double flow_reserve,
                   FlowPrescalingResult& out) {
  out.scale = 1.0;
  out.limit = ActiveLimit::kNone;
  out.limiting_cylinder = -1;
  double flow = 0.0;
  for (int i = 0; i < model.dof(); ++i) {
    const auto& cyl = model.cylinders[static_cast<std::size_t>(i)];
    const double v = dc_dq[i] * qdot[i];
    flow += dynamics::flow_area_m2(cyl, v) * std::abs(v);
    if (std::abs(v) * out.scale > cyl.v_max_m_s) {
      out.scale = cyl.v_max_m_s / std::abs(v);
      out.limit = ActiveLimit::kCylinderSpeed;
      out.limiting_cylinder = i;
    }
  }
  out.flow_demand_m3_s = flow;
  const double flow_budget = model.pump.max_flow_m3_s * (1.0 - flow_reserve);
  if (flow * out.scale > flow_budget) {
    out.scale = flow_budget / flow;
    out.limit = ActiveLimit::kFlow;
    out.limiting_cylinder = -1;
  }
}

}  // namespace craneassist::scaling
