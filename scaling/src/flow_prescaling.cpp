#include "craneassist/scaling/flow_prescaling.hpp"

#include <cmath>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/hydraulics.hpp"

namespace craneassist::scaling {

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
    flow += dynamics::cylinder_flow_m3_s(cyl, v);
    if (std::abs(v) * out.scale > cyl.v_max_m_s) {
      out.scale = cyl.v_max_m_s / std::abs(v);
      out.limit = ActiveLimit::kCylinderSpeed;
      out.limiting_cylinder = i;
    }
  }
  out.flow_demand_m3_s = flow;
  const double flow_budget = dynamics::flow_budget_m3_s(model, flow_reserve);
  if (flow * out.scale > flow_budget) {
    out.scale = flow_budget / flow;
    out.limit = ActiveLimit::kFlow;
    out.limiting_cylinder = -1;
  }
}

}  // namespace craneassist::scaling
