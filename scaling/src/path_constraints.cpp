#include "craneassist/scaling/path_constraints.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "craneassist/dynamics/hydraulics.hpp"

namespace craneassist::scaling {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTinyRate = 1e-12;

// Direction of cylinder i along the path (+1 extending, -1 retracting, 0 not moving).
double motion_sign(const PathGeometry& path, int i) {
  const double v = path.dc_dq[i] * path.f1[i];
  if (std::abs(v) < kTinyRate) return 0.0;
  return v > 0.0 ? 1.0 : -1.0;
}

// The chamber pressure per unit joint load (torque or force) of joint i moving along the path in
// the direction `sign`: sign / (dc/dq A), A the flow area of its cylinder's motion; times a
// joint's m(s) or b(s), the share of the load pressure they make.
double pressure_per_joint_load(const dynamics::CraneModel& model, const PathGeometry& path, int i,
                               double sign) {
  const double area = dynamics::flow_area_m2(model.cylinders[static_cast<std::size_t>(i)],
                                             path.dc_dq[i] * path.f1[i]);
  return sign / (path.dc_dq[i] * area);
}

// One side of a linear inequality k x + c <= limit, folded into [lo, hi].
void apply_upper(double k, double c, double limit, ActiveLimit kind, AccelerationBounds& b) {
  if (k > kTinyRate) {
    const double x = (limit - c) / k;
    if (x < b.sddot_max) {
      b.sddot_max = x;
      b.limit_max = kind;
    }
  } else if (k < -kTinyRate) {
    const double x = (limit - c) / k;
    if (x > b.sddot_min) {
      b.sddot_min = x;
      b.limit_min = kind;
    }
  } else if (c > limit) {
    // Not satisfiable by any acceleration at this speed: ask for the strongest deceleration the
    // other bounds allow; the speed limits bring the speed itself down.
    b.sddot_max = -kInf;
    b.limit_max = kind;
  }
}

// A pump-power (or supply-pressure) constraint k x + c <= limit (kind: kPower or kPressure,
// whichever sets the limit): it only ever caps the
// acceleration. Where slowing down would raise a load pressure past what the pump gives (k < 0:
// decelerating an over-running or heavy load), the constraint is left out: a pump short of
// power slows the motion, it never forces it to go faster, and a stop must always be possible.
// At sddot = 0 over the limit with no acceleration to help (k = 0), it asks for the strongest
// deceleration, as apply_upper does.
void apply_power(double k, double c, double limit, ActiveLimit kind, AccelerationBounds& b) {
  if (k < -kTinyRate) return;
  apply_upper(k, c, limit, kind, b);
}

// The pump-power bound for a constant-pressure pump: P = p_s Q(sdot) does not depend on the
// acceleration, so it is a speed limit alone, sdot <= P_max / (p_s Q / sdot); and a cylinder
// keeps its full flow while its load pressure stays dp_c below p_s, one inequality in sddot per
// moving cylinder (above it the section starves, pump_model.hpp).
void constant_pressure_bounds(const dynamics::CraneModel& model, const PathGeometry& path,
                              const dynamics::PathTerms& terms, double flow_per_speed,
                              double max_static_pressure, double p_max_w, AccelerationBounds& b) {
  const auto& pump = model.pump;
  const double p_supply = dynamics::supply_pressure_ceiling_pa(pump);
  b.pressure_limit_pa = p_supply - pump.ls_margin_pa;
  for (int i = 0; i < model.dof(); ++i) {
    const double sign = motion_sign(path, i);
    if (sign == 0.0) continue;
    const double scale = pressure_per_joint_load(model, path, i, sign);
    apply_power(scale * terms.m[i], scale * terms.b[i], b.pressure_limit_pa, ActiveLimit::kPressure,
                b);
  }
  if (flow_per_speed > 0.0 && p_supply > 0.0) {
    const bool starved = max_static_pressure > b.pressure_limit_pa;
    b.sdot_power = starved ? 0.0 : p_max_w / (p_supply * flow_per_speed);
    b.sdot_power_kind = starved ? ActiveLimit::kPressure : ActiveLimit::kPower;
  }
}

}  // namespace

void path_speed_limits(const dynamics::CraneModel& model, const PathGeometry& path,
                       double flow_reserve, SpeedLimits& out) {
  out.sdot_cylinder = kInf;
  out.cylinder = -1;
  double flow = 0.0;
  for (int i = 0; i < model.dof(); ++i) {
    const auto& cyl = model.cylinders[static_cast<std::size_t>(i)];
    const double v = path.dc_dq[i] * path.f1[i];  // cylinder velocity per unit path speed
    flow += dynamics::cylinder_flow_m3_s(cyl, v);
    // The reserve keeps room above the reference for the valves' feedback corrections, here as
    // for the pump flow: a fully open valve cannot correct anything.
    const double v_max = dynamics::cylinder_speed_cap_m_s(cyl, flow_reserve);
    if (std::abs(v) > kTinyRate && v_max / std::abs(v) < out.sdot_cylinder) {
      out.sdot_cylinder = v_max / std::abs(v);
      out.cylinder = i;
    }
  }
  out.flow_per_speed_m3 = flow;
  out.sdot_flow = flow > 0.0 ? dynamics::flow_budget_m3_s(model, flow_reserve) / flow : kInf;
}

void path_acceleration_bounds(const dynamics::CraneModel& model, const PathGeometry& path,
                              const dynamics::PathTerms& terms, double sdot,
                              const AccelerationLimits& limits, AccelerationBounds& b) {
  const int n = model.dof();
  b.sddot_min = -limits.path_deceleration_max;
  b.sddot_max = limits.path_acceleration_max;
  b.limit_min = ActiveLimit::kNone;
  b.limit_max = ActiveLimit::kNone;
  b.sdot_power = kInf;
  b.sdot_power_kind = ActiveLimit::kPower;
  b.sdot_acceleration = kInf;
  b.pressure_limit_pa = kInf;
  const double speed = std::max(sdot, 0.0);

  // Cylinder accelerations a_i = (r'_i f1_i^2 + r_i f2_i) sdot^2 + r_i f1_i sddot.
  for (int i = 0; i < n; ++i) {
    const double a_max = model.cylinders[static_cast<std::size_t>(i)].a_max_m_s2;
    const double k = path.dc_dq[i] * path.f1[i];
    const double curvature = path.d2c_dq2[i] * path.f1[i] * path.f1[i] + path.dc_dq[i] * path.f2[i];
    const double c = curvature * speed * speed;
    if (std::abs(curvature) > 0.0) {
      b.sdot_acceleration = std::min(b.sdot_acceleration, std::sqrt(a_max / std::abs(curvature)));
    }
    apply_upper(k, c, a_max, ActiveLimit::kCylinderAcceleration, b);
    apply_upper(-k, -c, a_max, ActiveLimit::kCylinderAcceleration, b);
  }

  const auto& pump = model.pump;
  const double p_max_w = pump.prime_mover_power_w * (1.0 - limits.power_reserve);
  if (limits.power_bound == PowerBound::kLoadSensing) {
    double flow_per_speed = 0.0;
    double max_static_pressure = -kInf;
    for (int i = 0; i < n; ++i) {
      const double sign = motion_sign(path, i);
      if (sign == 0.0) continue;
      const double v = path.dc_dq[i] * path.f1[i];
      flow_per_speed +=
          dynamics::cylinder_flow_m3_s(model.cylinders[static_cast<std::size_t>(i)], v);
      const double scale = pressure_per_joint_load(model, path, i, sign);
      max_static_pressure = std::max(max_static_pressure, scale * terms.b[i]);
    }
    if (pump.mode == dynamics::PumpMode::kConstantPressure) {
      constant_pressure_bounds(model, path, terms, flow_per_speed, max_static_pressure, p_max_w, b);
      return;
    }
    const double flow = flow_per_speed * speed;
    const double p_power = flow > 0.0 ? p_max_w / flow - pump.ls_margin_pa : kInf;
    const double p_relief = pump.max_pressure_pa - pump.ls_margin_pa;
    b.pressure_limit_pa = std::min(p_power, p_relief);
    // Which of the two sets the limit: the prime mover's power, or the relief valve.
    const ActiveLimit kind = p_power < p_relief ? ActiveLimit::kPower : ActiveLimit::kPressure;
    for (int i = 0; i < n; ++i) {
      const double sign = motion_sign(path, i);
      if (sign == 0.0) continue;
      const double scale = pressure_per_joint_load(model, path, i, sign);
      apply_power(scale * terms.m[i], scale * terms.b[i], b.pressure_limit_pa, kind, b);
    }
    // Quasi-static limit: the speed at which the current loads take exactly P_max at sddot = 0.
    if (flow_per_speed > 0.0) {
      const double p_supply = std::max(max_static_pressure, 0.0) + pump.ls_margin_pa;
      const bool beyond_relief = p_supply > p_relief + pump.ls_margin_pa;
      b.sdot_power = beyond_relief ? 0.0 : p_max_w / (p_supply * flow_per_speed);
      b.sdot_power_kind = beyond_relief ? ActiveLimit::kPressure : ActiveLimit::kPower;
    }
  } else if (limits.power_bound == PowerBound::kActuatorPowerSum) {
    // |sdot f1 . (m sddot + b)| <= P_max
    const double k = speed * path.f1.dot(terms.m);
    const double c = speed * path.f1.dot(terms.b);
    apply_power(k, c, p_max_w, ActiveLimit::kPower, b);
    apply_power(-k, -c, p_max_w, ActiveLimit::kPower, b);
    const double static_power_per_speed = std::abs(path.f1.dot(terms.b));
    if (static_power_per_speed > 0.0) {
      b.sdot_power = p_max_w / static_power_per_speed;
    }
  }
}

double load_sensing_power(const dynamics::CraneModel& model, const PathGeometry& path,
                          const dynamics::PathTerms& terms, double sdot, double sddot) {
  double flow = 0.0;
  double p_max = 0.0;
  for (int i = 0; i < model.dof(); ++i) {
    const double sign = motion_sign(path, i);
    if (sign == 0.0) continue;
    const double v = path.dc_dq[i] * path.f1[i];
    const double area = dynamics::flow_area_m2(model.cylinders[static_cast<std::size_t>(i)], v);
    flow += dynamics::cylinder_flow_m3_s(model.cylinders[static_cast<std::size_t>(i)], v) * sdot;
    p_max = std::max(p_max, sign * (terms.m[i] * sddot + terms.b[i]) / (path.dc_dq[i] * area));
  }
  return (p_max + model.pump.ls_margin_pa) * flow;
}

double pump_power(const dynamics::CraneModel& model, const PathGeometry& path,
                  const dynamics::PathTerms& terms, double sdot, double sddot) {
  if (model.pump.mode != dynamics::PumpMode::kConstantPressure) {
    return load_sensing_power(model, path, terms, sdot, sddot);
  }
  double flow = 0.0;
  for (int i = 0; i < model.dof(); ++i) {
    if (motion_sign(path, i) == 0.0) continue;
    const double v = path.dc_dq[i] * path.f1[i];
    flow += dynamics::cylinder_flow_m3_s(model.cylinders[static_cast<std::size_t>(i)], v) * sdot;
  }
  return dynamics::supply_pressure_ceiling_pa(model.pump) * flow;
}

}  // namespace craneassist::scaling
