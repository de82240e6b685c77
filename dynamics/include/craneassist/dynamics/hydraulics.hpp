// The hydraulic rules of a motion, once (docs/algorithms.md section 2): what a cylinder's
// velocity draws from the pump, what the pump and the cylinders allow with a reserve kept for
// the valves' feedback corrections, and the load pressure a cylinder force needs. The scaling's
// prescaling and path constraints, every redundancy resolution, the null space, the flow
// polytope, the planners and the simulator's flow accounting call these.
//
// Header-only and inline: each is a few operations in one fixed order, so a caller's result is
// the same to the last bit as the expression it replaces. No allocation, no exception.
#pragma once

#include <cmath>

#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

// The pump flow cylinder c draws at velocity v: its flow area times |v|, m^3/s.
inline double cylinder_flow_m3_s(const Cylinder& c, double v_m_s) {
  return flow_area_m2(c, v_m_s) * std::abs(v_m_s);
}

// The pump flow of a joint motion qdot at torque arms dc_dq: the sum over the cylinders of their
// flows at v_i = dc_dq_i qdot_i, m^3/s. With qdot = f' (per unit path speed), the flow per path
// speed, m^3 per m.
inline double joint_motion_flow_m3_s(const CraneModel& model, const JointVector& dc_dq,
                                     const JointVector& qdot) {
  double flow = 0.0;
  for (int i = 0; i < model.dof(); ++i) {
    flow += cylinder_flow_m3_s(model.cylinders[static_cast<std::size_t>(i)], dc_dq[i] * qdot[i]);
  }
  return flow;
}

// The pump flow the scaling may plan with: the pump's largest flow less the reserve share.
inline double flow_budget_m3_s(const CraneModel& model, double reserve) {
  return model.pump.max_flow_m3_s * (1.0 - reserve);
}

// The cylinder speed the scaling may plan with: its largest less the reserve share.
inline double cylinder_speed_cap_m_s(const Cylinder& c, double reserve) {
  return c.v_max_m_s * (1.0 - reserve);
}

// The pressure in the chamber that drives a cylinder with force F at velocity v: F over the flow
// area, signed so that it is positive when the motion works against the load, Pa.
inline double load_pressure_pa(const Cylinder& c, double force_n, double v_m_s) {
  return std::copysign(1.0, v_m_s) * force_n / flow_area_m2(c, v_m_s);
}

}  // namespace craneassist::dynamics
