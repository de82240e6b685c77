// Joint-to-cylinder geometry: cylinder length c_i(q_i), torque arm dc_i/dq_i and its derivative.
//
// The torque arm is signed: cylinder velocity v = dc/dq * qdot, and by virtual work the cylinder
// force is F = tau / (dc/dq). For the K70M tilt cylinder dc/dq < 0 (paper 000 writes v3 = -r3 q3dot
// with r3 = -dc3/dq3 > 0).
#pragma once

#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

double cylinder_length(const Cylinder& cylinder, double q);
double cylinder_arm(const Cylinder& cylinder, double q);        // dc/dq
double cylinder_arm_slope(const Cylinder& cylinder, double q);  // d2c/dq2

// Vector forms over all joints of the model.
void cylinder_lengths(const CraneModel& model, const JointVector& q, JointVector& c);
void cylinder_arms(const CraneModel& model, const JointVector& q, JointVector& dc_dq);

// Pump flow that the cylinder velocities v draw (sum of flow_area * |v|), m^3/s.
double pump_flow_demand(const CraneModel& model, const JointVector& cylinder_velocity);

}  // namespace craneassist::dynamics
