// The joint efforts that hold a serial chain still against gravity, analytically: for every body
// b (the payload included) and every joint i it rides on,
//     g_i = -m_b gravity . (z_{i-1} x (com_b - o_{i-1}))   (revolute)
//     g_i = -m_b gravity . z_{i-1}                          (prismatic),
// the same g as RigidBodyTerms::gravity (which probes the ODE model and costs a few ODE steps);
// this is a handful of vector operations per body, for the planners that need it at many poses.
#pragma once

#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

// g at q (N*m or N per joint). No allocation; data.frames are filled for q.
void static_gravity_effort(const CraneModel& model, KinematicsData& data, const JointVector& q,
                           JointVector& effort);

}  // namespace craneassist::dynamics
