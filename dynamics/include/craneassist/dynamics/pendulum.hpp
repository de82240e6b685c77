// The hanging grapple as a pendulum (docs/sway.md): the bodies at the tip (grapple and rotator)
// at CraneModel::grapple.com_below_m below the link's pivot and the load a point at
// load_below_m, swinging through small angles about a horizontal axis, damped by the link.
#pragma once

#include <Eigen/Core>

#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

// A body closer than this to the tip point is carried at the tip (the grapple and rotator).
inline constexpr double kAtTipM = 1e-3;

// Mass and inertia diagonal (about their centres) of the bodies at the tip point other than the
// payload: the grapple and rotator. No allocation.
void tip_bodies(const CraneModel& m, double& mass_kg, Eigen::Vector3d& inertia_kgm2) noexcept;

// Where the grapple hangs: along gravity, or down the base frame's z axis without gravity.
Eigen::Vector3d down_direction(const CraneModel& m) noexcept;

// The horizontal directions the swing is measured along at a tip (base frame): radial, from the
// slew axis (the base frame's z) out through the tip (x on the axis), and tangential, towards a
// positive slew (z x radial).
void swing_axes(const Eigen::Vector3d& tip_base, Eigen::Vector3d& radial,
                Eigen::Vector3d& tangential) noexcept;

// Where the grapple's centre of mass hangs (base frame) below a tip swung by radial_rad towards
// the reach and tangential_rad across it: what the simulator measures (MachineState::swing_*),
// drawn back. A model whose grapple does not hang, or a non-finite angle: the tip.
Eigen::Vector3d grapple_position(const CraneModel& m, const Eigen::Vector3d& tip_base,
                                 double radial_rad, double tangential_rad) noexcept;

// The swing from the vertical of a hanger whose angles towards the reach and across it are
// radial_rad and tangential_rad (each in its vertical plane, as a two-axis sensor measures them):
// atan(hypot(tan radial, tan tangential)). NaN where either is.
double swing_angle(double radial_rad, double tangential_rad) noexcept;

struct Pendulum {
  double omega_rad_s = 0.0;  // undamped natural frequency; 0: nothing hangs
  double zeta = 0.0;         // damping ratio of the link's damping
  double period_s() const;   // damped period (infinite when nothing hangs)
};

// The small-swing pendulum with payload_kg in the grapple (a compound pendulum: I_pivot theta'' +
// c theta' + g (m_g l_g + m_p l_p) theta = 0, the grapple's own inertia taken as the mean of its
// diagonal). A model whose grapple does not hang: omega 0. No allocation.
Pendulum grapple_pendulum(const CraneModel& m, double payload_kg) noexcept;

}  // namespace craneassist::dynamics
