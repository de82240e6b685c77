#include "craneassist/dynamics/resolutions.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "craneassist/dynamics/hydraulics.hpp"

namespace craneassist::dynamics {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTiny = 1e-12;

}  // namespace

const char* to_string(Resolution r) {
  switch (r) {
    case Resolution::kPinvJoint:
      return "pinv-joint";
    case Resolution::kPinvActuator:
      return "pinv-actuator";
    case Resolution::kMinFlow:
      return "min-flow";
    case Resolution::kMinLsPower:
      return "min-ls-power";
  }
  return "?";
}

Resolution energy_optimal_resolution(PumpMode mode) {
  return mode == PumpMode::kConstantPressure ? Resolution::kMinFlow : Resolution::kMinLsPower;
}

double resolution_cost(const CraneModel& model, Resolution resolution, const JointVector& qdot,
                       const JointVector& dc_dq, const JointVector* cylinder_force) {
  double squares = 0.0, flow = 0.0, p_max = 0.0;
  for (int i = 0; i < model.dof(); ++i) {
    const auto& cyl = model.cylinders[static_cast<std::size_t>(i)];
    const double v = dc_dq[i] * qdot[i];
    squares += v * v;
    flow += cylinder_flow_m3_s(cyl, v);
    if (cylinder_force != nullptr && std::abs(v) > kTiny) {
      p_max = std::max(p_max, load_pressure_pa(cyl, (*cylinder_force)[i], v));
    }
  }
  switch (resolution) {
    case Resolution::kPinvActuator:
      return squares;
    case Resolution::kMinFlow:
      return flow;
    case Resolution::kMinLsPower:
      return flow > 0.0 ? (p_max + model.pump.ls_margin_pa) * flow : 0.0;
    case Resolution::kPinvJoint:
      return qdot.squaredNorm();
  }
  return 0.0;
}

void resolve_by_extension(const CraneModel& model, Resolution resolution,
                          const ExtensionResolutionInput& in, ExtensionResolutionResult& out) {
  const int n = model.dof();
  const TaskJacobian& jac = *in.jacobian;
  const JointVector& arms = *in.dc_dq;
  out.qdot.setZero(n);
  out.feasible = false;
  out.extension_rate = 0.0;
  out.cost = 0.0;

  // qdot(t) = base + slope t (paper 000 eq. 34).
  const Eigen::Matrix3d j123 = jac.leftCols<3>();
  const Eigen::PartialPivLU<Eigen::Matrix3d> lu(j123);
  if (!(std::abs(lu.determinant()) > 1e-9)) return;
  const Eigen::Vector3d a = lu.solve(in.v_tip);
  const Eigen::Vector3d b = lu.solve(Eigen::Vector3d(jac.col(3)));
  JointVector base(n), slope(n);
  base << a, 0.0;
  slope << -b, 1.0;

  // The interval of t that keeps every joint within its rate bounds.
  double lo = -kInf, hi = kInf;
  for (int i = 0; i < n; ++i) {
    const double lower = in.bounds->lower[i], upper = in.bounds->upper[i];
    if (std::abs(slope[i]) > kTiny) {
      const double t1 = (lower - base[i]) / slope[i], t2 = (upper - base[i]) / slope[i];
      lo = std::max(lo, std::min(t1, t2));
      hi = std::min(hi, std::max(t1, t2));
    } else if (base[i] < lower - 1e-12 || base[i] > upper + 1e-12) {
      return;
    }
  }
  if (lo > hi) return;

  double best_t = std::clamp(0.0, lo, hi);
  if (resolution == Resolution::kPinvActuator) {
    // min sum (r_i (base_i + slope_i t))^2: a quadratic in t.
    double num = 0.0, den = 0.0;
    for (int i = 0; i < n; ++i) {
      const double r2 = arms[i] * arms[i];
      num += r2 * base[i] * slope[i];
      den += r2 * slope[i] * slope[i];
    }
    best_t = std::clamp(den > 0.0 ? -num / den : 0.0, lo, hi);
  } else {
    // Piecewise linear between breakpoints (a cylinder at rest): try them and the ends.
    std::array<double, kMaxJoints + 2> candidates{};
    std::size_t count = 0;
    if (std::isfinite(lo)) candidates[count++] = lo;
    if (std::isfinite(hi)) candidates[count++] = hi;
    for (int i = 0; i < n; ++i) {
      if (std::abs(slope[i]) <= kTiny) continue;
      const double t = -base[i] / slope[i];
      if (t >= lo && t <= hi) candidates[count++] = t;
    }
    double best_cost = kInf;
    JointVector qdot(n);
    for (std::size_t c = 0; c < count; ++c) {
      qdot = base + slope * candidates[c];
      const double cost = resolution_cost(model, resolution, qdot, arms, in.cylinder_force);
      if (cost < best_cost) {
        best_cost = cost;
        best_t = candidates[c];
      }
    }
  }
  out.extension_rate = best_t;
  out.qdot = base + slope * best_t;
  out.cost = resolution_cost(model, resolution, out.qdot, arms, in.cylinder_force);
  out.feasible = true;
}

}  // namespace craneassist::dynamics
