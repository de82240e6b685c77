#include "craneassist/valves/proportional_valves.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/dynamics/valve_table.hpp"

namespace craneassist::valves {

const char* to_string(PumpLimit limit) {
  switch (limit) {
    case PumpLimit::kNone:
      return "none";
    case PumpLimit::kMaxFlow:
      return "max_flow";
    case PumpLimit::kPower:
      return "power";
    case PumpLimit::kRelief:
      return "relief";
  }
  return "?";
}

const char* to_string(BackendStatus status) {
  switch (status) {
    case BackendStatus::kOk:
      return "ok";
    case BackendStatus::kNoData:
      return "no data";
    case BackendStatus::kFault:
      return "fault";
  }
  return "?";
}

ProportionalValves::ProportionalValves(const dynamics::CraneModel& model, double position_gain_1_s,
                                       double activation_speed_m_s, double activation_error_m)
    : model_(model),
      position_gain_1_s_(position_gain_1_s),
      activation_speed_m_s_(activation_speed_m_s),
      activation_error_m_(activation_error_m) {
  const auto& tables = model.valves.tables;
  for (std::size_t i = 0; i < tables.size() && i < tables_.size(); ++i) {
    if (!tables[i].empty()) tables_[i] = &tables[i];
  }
}

double ProportionalValves::spool_for(int i, double velocity_m_s) const {
  if (const auto* t = table(i)) return dynamics::valve_table_command(*t, velocity_m_s);
  return spool_from_velocity(velocity_m_s, model_.valves.dead_zone,
                             model_.cylinders[static_cast<std::size_t>(i)].v_max_m_s);
}

double ProportionalValves::dead_band_edge(int i, double side) const {
  if (const auto* t = table(i)) return dynamics::valve_table_dead_band_edge(*t, side);
  return side > 0.0 ? model_.valves.dead_zone : -model_.valves.dead_zone;
}

double ProportionalValves::velocity_from_spool(double spool, double dead_zone, double v_max) {
  const double open = std::clamp((std::abs(spool) - dead_zone) / (1.0 - dead_zone), 0.0, 1.0);
  return std::copysign(open * v_max, spool);
}

double ProportionalValves::spool_from_velocity(double velocity, double dead_zone, double v_max) {
  // Below this speed the command stays neutral instead of sitting at the dead-zone edge.
  constexpr double kMinFraction = 1e-4;
  const double fraction = std::min(std::abs(velocity) / v_max, 1.0);
  if (!(fraction > kMinFraction)) return 0.0;  // also catches NaN
  return std::copysign(dead_zone + (1.0 - dead_zone) * fraction, velocity);
}

void ProportionalValves::update(const ProportionalValvesInput& in, ValveCommand& out) const {
  const int n = model_.dof();
  out.spool.resize(n);
  for (int i = 0; i < n; ++i) {
    if (std::abs(in.velocity_ref_m_s[i]) < activation_speed_m_s_ &&
        std::abs(in.position_error_m[i]) < activation_error_m_) {
      out.spool[i] = 0.0;  // at rest and close enough: the section stays closed
      continue;
    }
    const double v = in.velocity_ref_m_s[i] + position_gain_1_s_ * in.position_error_m[i];
    out.spool[i] = spool_for(i, v);
  }
}

}  // namespace craneassist::valves
