#include "craneassist/dynamics/pendulum.hpp"

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
