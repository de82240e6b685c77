#include "craneassist/sim_backend/pump_model.hpp"

#include <algorithm>
#include <cmath>

namespace craneassist::sim_backend {

void PumpModel::set_flow_limit(double flow_m3_s) noexcept {
  // NaN goes to 0: a consumer that cannot say what it leaves leaves nothing.
  flow_limit_m3_s_ = flow_m3_s > 0.0 ? std::min(flow_m3_s, pump_.max_flow_m3_s) : 0.0;
}

double PumpModel::deliverable_flow(double p) const {
  if (p <= 0.0) return flow_limit_m3_s_;
  return std::min(flow_limit_m3_s_, pump_.prime_mover_power_w / p);
}

double PumpModel::section_flows(const JointVector& demand, const JointVector& load, double p,
                                JointVector* fraction) const {
  double total = 0.0;
  for (int k = 0; k < demand.size(); ++k) {
    const double f =
        demand[k] > 0.0 ? std::sqrt(std::clamp((p - load[k]) / pump_.ls_margin_pa, 0.0, 1.0)) : 0.0;
    if (fraction != nullptr) (*fraction)[k] = f;
    total += f * demand[k];
  }
  return total;
}

void PumpModel::solve(const JointVector& demand, const JointVector& load, PumpResult& out) const {
  const int n = static_cast<int>(demand.size());
  out.delivered_fraction.setZero(n);
  double max_load = 0.0;
  bool any = false;
  for (int k = 0; k < n; ++k) {
    if (demand[k] > 0.0) {
      max_load = any ? std::max(max_load, load[k]) : load[k];
      any = true;
    }
  }
  const bool constant_pressure = pump_.mode == dynamics::PumpMode::kConstantPressure;
  const double p_ceiling = dynamics::supply_pressure_ceiling_pa(pump_);
  out.limit = valves::PumpLimit::kNone;
  if (!any) {
    // An idle LS pump sits at standby; a CP pump holds its setpoint at zero displacement.
    out.supply_pressure_pa = constant_pressure ? p_ceiling : pump_.standby_pressure_pa;
    out.flow_m3_s = 0.0;
    out.power_w = 0.0;
    return;
  }
  // The pressure every open section needs for its full flow: highest load + margin. An
  // unsaturated LS pump supplies just that (at least standby); a CP pump supplies p_s whatever
  // it is. Either way at most the ceiling (relief, or p_s).
  const double p_needed = std::max(max_load, 0.0) + pump_.ls_margin_pa;
  const double p_ls = std::max(p_needed, pump_.standby_pressure_pa);
  const double p_top = constant_pressure ? p_ceiling : std::min(p_ls, p_ceiling);
  double p = p_top;
  if (section_flows(demand, load, p_top, nullptr) > deliverable_flow(p_top)) {
    // Saturated: the balance sum Q_k(p) = Q_pump(p) has one root (left side rises with p, right
    // side falls). Bisection, fixed iteration count.
    double lo = 0.0, hi = p_top;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (section_flows(demand, load, mid, nullptr) > deliverable_flow(mid)) {
        hi = mid;
      } else {
        lo = mid;
      }
    }
    p = lo;
    out.limit = pump_.prime_mover_power_w / std::max(p, 1.0) < flow_limit_m3_s_
                    ? valves::PumpLimit::kPower
                    : valves::PumpLimit::kMaxFlow;
  } else if ((constant_pressure ? p_needed : p_ls) > p_ceiling) {
    out.limit = valves::PumpLimit::kRelief;
  }
  out.flow_m3_s = section_flows(demand, load, p, &out.delivered_fraction);
  // Over-running sections take flow even at zero supply pressure; when that alone is more than
  // the pump can deliver (a flow limit cut down by another consumer, set_flow_limit) they share
  // what it delivers in proportion: their inlet chambers cannot fill faster than the pump.
  const double deliverable = deliverable_flow(p);
  if (out.flow_m3_s > deliverable) {
    const double k = out.flow_m3_s > 0.0 ? deliverable / out.flow_m3_s : 0.0;
    out.delivered_fraction *= k;
    out.flow_m3_s = deliverable;
    out.limit = valves::PumpLimit::kMaxFlow;
  }
  out.supply_pressure_pa = std::max(p, 0.0);
  out.power_w = out.supply_pressure_pa * out.flow_m3_s;
}

}  // namespace craneassist::sim_backend
