#include "craneassist/dynamics/static_gravity.hpp"

namespace craneassist::dynamics {

void static_gravity_effort(const CraneModel& model, KinematicsData& data, const JointVector& q,
                           JointVector& effort) {
  forward_kinematics(model, data, q);
  const int n = model.dof();
  effort.setZero(n);
  for (const Body& body : model.bodies) {
    if (body.frame < 1 || body.frame > n || !(body.mass_kg > 0.0)) continue;
    const Eigen::Vector3d com = data.frames[static_cast<std::size_t>(body.frame)] * body.com_m;
    const Eigen::Vector3d weight = body.mass_kg * model.gravity_m_s2;
    for (int i = 0; i < body.frame; ++i) {
      const auto& frame = data.frames[static_cast<std::size_t>(i)];
      const Eigen::Vector3d z = frame.linear().col(2);
      const double generalized =
          model.joints[static_cast<std::size_t>(i)].type == JointType::kRevolute
              ? z.cross(com - frame.translation()).dot(weight)
              : z.dot(weight);
      effort[i] -= generalized;
    }
  }
}

}  // namespace craneassist::dynamics
