// Quasi-static load-sensing pump with a power-limiting valve and NO flow sharing.
//
// Each open valve section k asks for flow Q_k (its pressure compensator holds the main-spool drop
// at dp_c while it can) against a load pressure p_k. The pump delivers Q_pump(p) =
// min(Q_max, P_max / p) at supply pressure p and raises p to max_k p_k + dp_LS when it can. When
// the demand exceeds what it can deliver, the supply pressure settles where the section flows
//     Q_k(p) = Q_k * sqrt(clamp((p - p_k) / dp_c, 0, 1))
// add up to the delivery: the section with the highest load pressure loses its margin first and
// starves first, the behaviour that makes a boom tip dip on a real LS machine ("Real-time
// trajectory scaling algorithm for hydraulic manipulators subject to limited on-board power",
// section 1). The relief valve caps p at max_pressure.
#pragma once

#include "craneassist/dynamics/model.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::sim_backend {

using dynamics::JointVector;

struct PumpResult {
  JointVector delivered_fraction;  // Q_k(p) / Q_k per section, in [0, 1]
  double supply_pressure_pa = 0.0;
  double flow_m3_s = 0.0;
  double power_w = 0.0;
  valves::PumpLimit limit = valves::PumpLimit::kNone;
};

class PumpModel {
 public:
  explicit PumpModel(const dynamics::Pump& pump) : pump_(pump) {}

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
};

}  // namespace craneassist::sim_backend
