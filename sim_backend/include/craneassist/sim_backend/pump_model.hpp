// Quasi-static variable-displacement pump with a power-limiting valve and pressure-compensated
// valve sections with NO flow sharing, in one of two modes (dynamics::PumpMode):
//
// Load sensing (default). Each open valve section k asks for flow Q_k (its pressure compensator
// holds the main-spool drop at dp_c while it can) against a load pressure p_k. The pump delivers
// Q_pump(p) = min(Q_max, P_max / p) at supply pressure p and raises p to max_k p_k + dp_LS when
// it can. When the demand exceeds what it can deliver, the supply pressure settles where the
// section flows
//     Q_k(p) = Q_k * sqrt(clamp((p - p_k) / dp_c, 0, 1))
// add up to the delivery: the section with the highest load pressure loses its margin first and
// starves first, the behaviour that makes a boom tip dip on a real LS machine ("Real-time
// trajectory scaling algorithm for hydraulic manipulators subject to limited on-board power",
// section 1). The relief valve caps p at max_pressure. dp_c = dp_LS = ls_margin.
//
// Constant pressure (paper 000, fig. 3b and section 4.3). The pump's pressure compensator holds
// the supply at the setpoint p_s (capped by the relief) whatever the loads, the displacement
// following the demand up to Q_pump(p_s) = min(Q_max, P_max / p_s). The sections see the same
// compensator law at p = p_s, so a section whose load pressure is within dp_c of p_s gets less
// than it asks for and one at or above p_s gets nothing (its load-holding check valve keeps it
// still). When the demand exceeds Q_pump(p_s) the displacement is at its limit, the pump can no
// longer hold p_s, and the supply pressure falls to where the compensated section flows add up
// to Q_pump(p): the same balance as an LS pump, so again no flow sharing, the most loaded
// section starving first. (Flow sharing, every section cut by the same factor, needs
// post-compensated LUDV sections, which these are not.) The pump is an ideal variable pump: no
// flow, no power (a real one spends some leakage and friction power holding p_s); power is the
// supply pressure times the delivered flow, p_s Q unless saturated.
#pragma once

#include "craneassist/dynamics/model.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::sim_backend {

using dynamics::JointVector;

struct PumpResult {
  JointVector delivered_fraction;  // Q_k(p) / Q_k per section, in [0, 1]
  // The supply pressure p, the delivered flow, p times it, and what held the flow back: the
  // flow or power limit (saturated), or the pressure ceiling (relief in LS mode, p_s in CP mode)
  // below the most loaded open section's load pressure + dp_c.
  double supply_pressure_pa = 0.0;
  double flow_m3_s = 0.0;
  double power_w = 0.0;
  valves::PumpLimit limit = valves::PumpLimit::kNone;
};

class PumpModel {
 public:
  explicit PumpModel(const dynamics::Pump& pump)
      : pump_(pump), flow_limit_m3_s_(pump.max_flow_m3_s) {}

  // The most the pump may deliver from now on: its max_flow, or less when another consumer on
  // the same pump takes the rest (a crane sharing its pump with a drive, docs/mobile.md). Clamped
  // to [0, max_flow]; no allocation.
  void set_flow_limit(double flow_m3_s) noexcept;
  double flow_limit() const noexcept { return flow_limit_m3_s_; }

  // demand_m3_s: flow each section asks for (>= 0); load_pressure_pa: its load pressure
  // (negative for an over-running load). Bounded work (fixed bisection count), no allocation.
  void solve(const JointVector& demand_m3_s, const JointVector& load_pressure_pa,
             PumpResult& out) const;

  // Most the pump can deliver at supply pressure p.
  double deliverable_flow(double pressure_pa) const;

 private:
  double section_flows(const JointVector& demand, const JointVector& load, double p,
                       JointVector* fraction) const;

  dynamics::Pump pump_;
  double flow_limit_m3_s_;
};

}  // namespace craneassist::sim_backend
