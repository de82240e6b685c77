#include "craneassist/mhsb/mhsb.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "craneassist/dynamics/hydraulics.hpp"

namespace craneassist::mhsb {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinArm = 1e-12;  // as joint_velocity_set(): no torque arm

std::size_t at(int i) {
  return static_cast<std::size_t>(i);
}

// K = Q_R / sqrt(P_R), m^3/(s Pa^0.5).
double valve_coefficient(const ServoValve& valve) {
  return valve.rated_flow_m3_s / std::sqrt(valve.rated_pressure_drop_pa);
}

double cube_sum(const Cylinder& c) {
  return c.area_a_m2 * c.area_a_m2 * c.area_a_m2 + c.area_b_m2 * c.area_b_m2 * c.area_b_m2;
}

}  // namespace

const char* to_string(MhsbMode mode) {
  switch (mode) {
    case MhsbMode::kNormal:
      return "N";
    case MhsbMode::kDecoupledBoost:
      return "DB";
    case MhsbMode::kSharedBoost:
      return "SB";
  }
  return "?";
}

std::optional<MhsbMode> parse_mhsb_mode(std::string_view text) {
  return parse_name(kMhsbModes, text);
}

int modules_used(MhsbMode mode) {
  return mode == MhsbMode::kNormal ? 0 : mode == MhsbMode::kDecoupledBoost ? 1 : 2;
}

int ModePattern::modules() const {
  int n = 0;
  for (int j = 0; j < dof; ++j) n += modules_used(mode[at(j)]);
  return n;
}

int ModePattern::switches_from(const ModePattern& other) const {
  int n = 0;
  for (int j = 0; j < dof; ++j) n += mode[at(j)] != other.mode[at(j)] ? 1 : 0;
  return n;
}

std::string to_string(const ModePattern& pattern) {
  std::string text;
  for (int j = 0; j < pattern.dof; ++j) {
    if (j > 0) text += '-';
    text += to_string(pattern.mode[at(j)]);
  }
  return text;
}

std::optional<ModePattern> parse_mode_pattern(std::string_view text, int dof) {
  if (dof < 1 || dof > kMaxJoints) return std::nullopt;
  ModePattern pattern;
  pattern.dof = dof;
  for (int j = 0; j < dof; ++j) {
    const std::size_t end = text.find('-');
    if ((end == std::string_view::npos) != (j == dof - 1)) return std::nullopt;
    const auto mode = parse_mhsb_mode(text.substr(0, end));
    if (!mode) return std::nullopt;
    pattern.mode[at(j)] = *mode;
    text = end == std::string_view::npos ? std::string_view{} : text.substr(end + 1);
  }
  return pattern;
}

std::vector<ModePattern> mode_patterns(int dof, int modules) {
  std::vector<ModePattern> out;
  if (dof < 1 || dof > kMaxJoints) return out;
  int count = 1;
  for (int j = 0; j < dof; ++j) count *= 3;
  for (int code = 0; code < count; ++code) {
    ModePattern p;
    p.dof = dof;
    int rest = code;
    for (int j = dof - 1; j >= 0; --j) {
      p.mode[at(j)] = kMhsbModes[at(rest % 3)];
      rest /= 3;
    }
    if (p.modules() <= modules) out.push_back(p);
  }
  return out;
}

CylinderSpeeds servo_valve_speeds(const Cylinder& c, const ServoValve& valve, double supply_pa,
                                  double tank_pa, double force_n) {
  const double k = valve_coefficient(valve);
  const double s = cube_sum(c);
  const double ext = c.area_a_m2 * supply_pa - force_n - c.area_b_m2 * tank_pa;
  const double ret = c.area_b_m2 * supply_pa + force_n - c.area_a_m2 * tank_pa;
  return {ext > 0.0 ? k * std::sqrt(ext / s) : 0.0, ret > 0.0 ? k * std::sqrt(ret / s) : 0.0};
}

double required_supply_pressure_pa(const Cylinder& c, const ServoValve& valve, double tank_pa,
                                   double force_n, double v_m_s) {
  const double k = valve_coefficient(valve);
  const double drop = cube_sum(c) * v_m_s * v_m_s / (k * k);
  if (v_m_s >= 0.0) return (force_n + c.area_b_m2 * tank_pa + drop) / c.area_a_m2;
  return (-force_n + c.area_a_m2 * tank_pa + drop) / c.area_b_m2;
}

double mode_supply_pressure_pa(const CraneModel& model, MhsbMode mode) {
  const double p0 = model.pump.supply_pressure_pa;
  if (mode == MhsbMode::kNormal || !model.mhsb) return p0;
  return std::min(p0 + model.mhsb->max_boost_pa, model.pump.max_pressure_pa);
}

double mode_flow_cap_m3_s(const Mhsb& mhsb, MhsbMode mode) {
  return mode == MhsbMode::kNormal ? kInf : modules_used(mode) * mhsb.servo_pump_max_flow_m3_s;
}

bool needs_boost(const CraneModel& model, int joint, double force_n, double v_m_s) {
  if (!model.mhsb || !positive_load(force_n, v_m_s)) return false;
  const Mhsb& m = *model.mhsb;
  return required_supply_pressure_pa(model.cylinders[at(joint)], m.valve, m.tank_pressure_pa,
                                     force_n, v_m_s) > model.pump.supply_pressure_pa;
}

bool mode_allowed(const CraneModel& model, int joint, MhsbMode mode, double force_n, double v_m_s) {
  return needs_boost(model, joint, force_n, v_m_s) ? is_boost(mode) : mode == MhsbMode::kNormal;
}

void mhsb_joint_velocity_set(const CraneModel& model, const JointVector& q,
                             const JointVector& dc_dq, const JointVector& cylinder_force_n,
                             const ModePattern& pattern, const FlowPolytopeSettings& settings,
                             JointVelocitySet& out) {
  joint_velocity_set(model, q, dc_dq, settings, out);
  if (!model.mhsb) return;
  const Mhsb& m = *model.mhsb;
  const double keep = 1.0 - settings.cylinder_speed_reserve;
  for (int i = 0; i < model.dof(); ++i) {
    const double r = dc_dq[i];
    if (!(std::abs(r) > kMinArm)) continue;
    const Cylinder& c = model.cylinders[at(i)];
    const MhsbMode mode = pattern.mode[at(i)];
    const CylinderSpeeds valve = servo_valve_speeds(
        c, m.valve, mode_supply_pressure_pa(model, mode), m.tank_pressure_pa, cylinder_force_n[i]);
    const double cap = mode_flow_cap_m3_s(m, mode);
    const double extend = keep * std::min(valve.extend_m_s, cap / flow_area_m2(c, 1.0));
    const double retract = keep * std::min(valve.retract_m_s, cap / flow_area_m2(c, -1.0));
    // A positive joint rate moves the cylinder in the sign of r.
    const double up = (r > 0.0 ? extend : retract) / std::abs(r);
    const double down = (r > 0.0 ? retract : extend) / std::abs(r);
    out.qdot_max[i] = std::min(out.qdot_max[i], up);
    out.qdot_min[i] = std::max(out.qdot_min[i], -down);
  }
}

const char* to_string(MhsbEnergyModel model) {
  return model == MhsbEnergyModel::kPaper ? "paper" : "series";
}

std::optional<MhsbEnergyModel> parse_mhsb_energy_model(std::string_view text) {
  return parse_name(kMhsbEnergyModels, text);
}

double mhsb_actuator_power_w(const CraneModel& model, int joint, MhsbMode mode, double force_n,
                             double v_m_s, MhsbEnergyModel energy_model) {
  const Cylinder& c = model.cylinders[at(joint)];
  const double p0 = model.pump.supply_pressure_pa;
  const double leak = model.mhsb ? model.mhsb->valve.leakage_m3_s : 0.0;
  const double flow = dynamics::cylinder_flow_m3_s(c, v_m_s);
  if (mode == MhsbMode::kNormal || !model.mhsb) return p0 * (flow + leak);
  const Mhsb& m = *model.mhsb;
  const double ps =
      std::max(p0, required_supply_pressure_pa(c, m.valve, m.tank_pressure_pa, force_n, v_m_s));
  if (energy_model == MhsbEnergyModel::kPaper) {
    return ps * flow / m.servo_pump_efficiency + ps * leak;
  }
  return (p0 + (ps - p0) / m.servo_pump_efficiency) * (flow + leak);
}

}  // namespace craneassist::mhsb
