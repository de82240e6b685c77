// A random tip task of the K70M for the redundancy-resolution tests (test_resolutions.cpp,
// test_null_space_resolution.cpp): a pose inside the joint ranges, its tip Jacobian, a random tip
// velocity, the cylinder lever arms and random cylinder forces.
#pragma once

#include <random>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/kinematics.hpp"

namespace craneassist::test {

inline const dynamics::CraneModel& k70m() {
  static const dynamics::CraneModel model = config::default_crane_config().model;
  return model;
}

struct RandomTipTask {
  dynamics::JointVector q;
  dynamics::TaskJacobian jacobian;
  Eigen::Vector3d v;
  dynamics::JointVector arms;
  dynamics::JointVector force;
};

// Each joint uniform in its range less 0.05 from either end, each tip velocity component normal
// with standard deviation velocity_sd, each cylinder force normal with 50 kN.
inline RandomTipTask random_tip_task(std::mt19937& rng, double velocity_sd) {
  const auto& m = k70m();
  RandomTipTask c;
  c.q.resize(4);
  for (int i = 0; i < 4; ++i) {
    std::uniform_real_distribution<double> d(m.joints[i].q_min + 0.05, m.joints[i].q_max - 0.05);
    c.q[i] = d(rng);
  }
  dynamics::KinematicsData kin;
  dynamics::tip_jacobian(m, kin, c.q, c.jacobian);
  std::normal_distribution<double> nd(0.0, velocity_sd);
  c.v = Eigen::Vector3d(nd(rng), nd(rng), nd(rng));
  dynamics::cylinder_arms(m, c.q, c.arms);
  std::normal_distribution<double> force(0.0, 5e4);
  c.force.resize(4);
  for (int i = 0; i < 4; ++i) c.force[i] = force(rng);
  return c;
}

}  // namespace craneassist::test
