#include "craneassist/dynamics/pendulum.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace craneassist::dynamics {

void tip_bodies(const CraneModel& m, double& mass_kg, Eigen::Vector3d& inertia_kgm2) noexcept {
  mass_kg = 0.0;
  inertia_kgm2.setZero();
  for (const auto& b : m.bodies) {
    if (b.frame == m.dof() && b.com_m.norm() < kAtTipM && !is_payload(b)) {
      mass_kg += b.mass_kg;
      inertia_kgm2 += b.inertia_diag_kgm2;
    }
  }
}

Eigen::Vector3d down_direction(const CraneModel& m) noexcept {
  const double g = m.gravity_m_s2.norm();
  return g > 1e-9 ? Eigen::Vector3d(m.gravity_m_s2 / g) : Eigen::Vector3d(0.0, 0.0, -1.0);
}

void swing_axes(const Eigen::Vector3d& tip_base, Eigen::Vector3d& radial,
                Eigen::Vector3d& tangential) noexcept {
  radial = Eigen::Vector3d(tip_base.x(), tip_base.y(), 0.0);
  radial = radial.norm() > 1e-9 ? Eigen::Vector3d(radial.normalized()) : Eigen::Vector3d::UnitX();
  tangential = Eigen::Vector3d::UnitZ().cross(radial);
}

Eigen::Vector3d grapple_position(const CraneModel& m, const Eigen::Vector3d& tip_base,
                                 double radial_rad, double tangential_rad) noexcept {
  if (!m.grapple.hangs() || !std::isfinite(radial_rad) || !std::isfinite(tangential_rad)) {
    return tip_base;
  }
  Eigen::Vector3d radial, tangential;
  swing_axes(tip_base, radial, tangential);
  const Eigen::Vector3d along =
      down_direction(m) + std::tan(radial_rad) * radial + std::tan(tangential_rad) * tangential;
  return tip_base + m.grapple.com_below_m * along.normalized();
}

double swing_angle(double radial_rad, double tangential_rad) noexcept {
  return std::atan(std::hypot(std::tan(radial_rad), std::tan(tangential_rad)));
}

double Pendulum::period_s() const {
  if (!(omega_rad_s > 0.0) || !(zeta < 1.0)) return std::numeric_limits<double>::infinity();
  return 2.0 * M_PI / (omega_rad_s * std::sqrt(1.0 - zeta * zeta));
}

Pendulum grapple_pendulum(const CraneModel& m, double payload_kg) noexcept {
  Pendulum p;
  const auto& g = m.grapple;
  if (!g.hangs()) return p;
  double mass_kg = 0.0;
  Eigen::Vector3d inertia;
  tip_bodies(m, mass_kg, inertia);
  const double load_kg = std::max(payload_kg, 0.0);
  const double inertia_pivot = mass_kg * g.com_below_m * g.com_below_m + inertia.mean() +
                               load_kg * g.load_below_m * g.load_below_m;
  const double stiffness =
      m.gravity_m_s2.norm() * (mass_kg * g.com_below_m + load_kg * g.load_below_m);
  if (!(inertia_pivot > 0.0 && stiffness > 0.0)) return p;
  p.omega_rad_s = std::sqrt(stiffness / inertia_pivot);
  p.zeta = g.damping_n_m_s_rad / (2.0 * inertia_pivot * p.omega_rad_s);
  return p;
}

}  // namespace craneassist::dynamics
