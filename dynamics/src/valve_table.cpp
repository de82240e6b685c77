#include "craneassist/dynamics/valve_table.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace craneassist::dynamics {
namespace {

// Below this share of the top speed the command stays neutral (as spool_from_velocity).
constexpr double kMinFraction = 1e-4;

double lerp(double x0, double y0, double x1, double y1, double x) {
  return y0 + (y1 - y0) * (x - x0) / (x1 - x0);
}

}  // namespace

std::string check_valve_table(const ValveTable& table) {
  const auto& c = table.command;
  const auto& v = table.velocity_m_s;
  std::ostringstream why;
  if (c.size() != v.size()) {
    why << "command has " << c.size() << " points, velocity " << v.size()
        << " (one velocity per command)";
    return why.str();
  }
  if (c.size() < 2) return "needs at least 2 points";
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (!std::isfinite(c[k]) || c[k] < -1.0 || c[k] > 1.0) {
      why << "command point " << k + 1 << " (" << c[k] << ") must lie in [-1, 1]";
      return why.str();
    }
    if (!std::isfinite(v[k])) {
      why << "velocity point " << k + 1 << " is not finite";
      return why.str();
    }
    if (k == 0) continue;
    if (!(c[k] > c[k - 1])) {
      why << "commands must increase strictly: point " << k + 1 << " (" << c[k]
          << ") does not exceed point " << k << " (" << c[k - 1] << ")";
      return why.str();
    }
    if (v[k] < v[k - 1]) {
      why << "not monotone: velocity point " << k + 1 << " (" << v[k] << " m/s at command " << c[k]
          << ") is below point " << k << " (" << v[k - 1] << " m/s at command " << c[k - 1] << ")";
      return why.str();
    }
    if (v[k] == v[k - 1] && v[k] != 0.0) {
      why << "velocity points " << k << " and " << k + 1 << " are equal (" << v[k]
          << " m/s) outside the dead band: the table could not be inverted there";
      return why.str();
    }
  }
  if (!(v.front() < 0.0 && v.back() > 0.0)) {
    return "needs both directions: the first velocity negative (retraction), the last positive "
           "(extension)";
  }
  return {};
}

double valve_table_velocity(const ValveTable& table, double command) {
  const auto& c = table.command;
  const auto& v = table.velocity_m_s;
  if (!(command > c.front())) return v.front();  // also NaN
  if (command >= c.back()) return v.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(c.begin(), c.end(), command) -
                                          c.begin());  // c[k-1] <= command < c[k]
  return lerp(c[k - 1], v[k - 1], c[k], v[k], command);
}

double valve_table_command(const ValveTable& table, double velocity_m_s) {
  const auto& c = table.command;
  const auto& v = table.velocity_m_s;
  if (velocity_m_s > 0.0) {
    if (!(velocity_m_s > kMinFraction * v.back())) return 0.0;
    if (velocity_m_s >= v.back()) return c.back();
    // First point at or above the velocity; v.front() < 0 so k >= 1, and v[k-1] < velocity.
    const auto k =
        static_cast<std::size_t>(std::lower_bound(v.begin(), v.end(), velocity_m_s) - v.begin());
    return lerp(v[k - 1], c[k - 1], v[k], c[k], velocity_m_s);
  }
  if (!(velocity_m_s < kMinFraction * v.front())) return 0.0;  // also NaN
  if (velocity_m_s <= v.front()) return c.front();
  // Last point at or below the velocity: k; v[k+1] > velocity.
  const auto k =
      static_cast<std::size_t>(std::upper_bound(v.begin(), v.end(), velocity_m_s) - v.begin()) - 1;
  return lerp(v[k], c[k], v[k + 1], c[k + 1], velocity_m_s);
}

double valve_table_dead_band_edge(const ValveTable& table, double side) {
  const auto& c = table.command;
  const auto& v = table.velocity_m_s;
  if (side > 0.0) {
    // The last point not moving out; the next one does (v.back() > 0).
    const auto k =
        static_cast<std::size_t>(std::upper_bound(v.begin(), v.end(), 0.0) - v.begin()) - 1;
    return v[k] == 0.0 ? c[k] : lerp(v[k], c[k], v[k + 1], c[k + 1], 0.0);
  }
  // The first point not moving in; the one before does (v.front() < 0).
  const auto k = static_cast<std::size_t>(std::lower_bound(v.begin(), v.end(), 0.0) - v.begin());
  return v[k] == 0.0 ? c[k] : lerp(v[k - 1], c[k - 1], v[k], c[k], 0.0);
}

namespace {
const ValveTable* section_table(const CraneModel& model, int i) {
  const auto& tables = model.valves.tables;
  return i >= 0 && static_cast<std::size_t>(i) < tables.size()
             ? &tables[static_cast<std::size_t>(i)]
             : nullptr;
}
}  // namespace

double section_time_constant_s(const CraneModel& model, int i) {
  const ValveTable* t = section_table(model, i);
  return t != nullptr && std::isfinite(t->time_constant_s) ? t->time_constant_s
                                                           : model.valves.time_constant_s;
}

double section_delay_s(const CraneModel& model, int i) {
  const ValveTable* t = section_table(model, i);
  return t != nullptr && std::isfinite(t->delay_s) ? t->delay_s : model.valves.delay_s;
}

double longest_valve_lag_s(const CraneModel& model) {
  double lag = model.valves.delay_s + model.valves.time_constant_s;
  for (int i = 0; i < model.dof(); ++i) {
    lag = std::max(lag, section_delay_s(model, i) + section_time_constant_s(model, i));
  }
  return lag;
}

ValveTable straight_line_valve_table(double dead_zone, double v_max_m_s) {
  ValveTable t;
  if (dead_zone > 0.0) {
    t.command = {-1.0, -dead_zone, dead_zone, 1.0};
    t.velocity_m_s = {-v_max_m_s, 0.0, 0.0, v_max_m_s};
  } else {
    t.command = {-1.0, 0.0, 1.0};
    t.velocity_m_s = {-v_max_m_s, 0.0, v_max_m_s};
  }
  return t;
}

}  // namespace craneassist::dynamics
