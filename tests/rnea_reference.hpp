// Shared test reference: the K70M and planar 2R test models, an independent recursive
// Newton-Euler (RNEA) implementation, and random sampling helpers. Used by test_rigid_body.cpp and
// test_path_dynamics.cpp; written from scratch, independent of the dynamics library's algorithms.
#pragma once

#include <Eigen/Geometry>
#include <numbers>
#include <random>
#include <vector>

#include "craneassist/dynamics/model.hpp"

namespace craneassist::test {

using craneassist::dynamics::Body;
using craneassist::dynamics::CraneModel;
using craneassist::dynamics::DhJoint;
using craneassist::dynamics::JointMatrix;
using craneassist::dynamics::JointType;
using craneassist::dynamics::JointVector;

inline constexpr double kPi = std::numbers::pi;

// ---------------------------------------------------------------------------------------------
// Models

inline DhJoint joint(const char* name, JointType type, double a, double alpha, double d,
                     double theta, double q_min, double q_max) {
  DhJoint j;
  j.name = name;
  j.type = type;
  j.a_m = a;
  j.alpha_rad = alpha;
  j.d_m = d;
  j.theta_rad = theta;
  j.q_min = q_min;
  j.q_max = q_max;
  return j;
}

inline Body body(const char* name, int frame, double mass, Eigen::Vector3d com,
                 Eigen::Vector3d inertia) {
  Body b;
  b.name = name;
  b.frame = frame;
  b.mass_kg = mass;
  b.com_m = com;
  b.inertia_diag_kgm2 = inertia;
  return b;
}

// The K70M reference crane (reference-crane.md).
inline CraneModel k70m(double payload_kg = 650.0) {
  CraneModel m;
  m.name = "K70M";
  m.joints = {
      joint("slew", JointType::kRevolute, -0.208, kPi / 2, 1.605, 0.0, -kPi, kPi),
      joint("lift", JointType::kRevolute, 3.504, 0.0, 0.0, 0.0, -0.425, 1.097),
      joint("tilt", JointType::kRevolute, 0.376, kPi / 2, 0.0, kPi / 2, -2.75, -0.25),
      joint("extension", JointType::kPrismatic, 0.0, -kPi / 2, 2.13, 0.0, 0.0, 3.7),
  };
  m.bodies = {
      body("pillar", 1, 500, {0.208, -0.805, 0}, {118, 22.5, 118}),
      body("inner boom", 2, 420, {-1.754, 0, 0}, {10, 429, 429}),
      body("outer boom", 3, 300, {0, 0, 1.1}, {156, 156, 8}),
      body("telescopes", 4, 160, {0, 1.85, 0}, {182, 4, 182}),
      body("grapple", 4, 180, {0, 0, 0}, {6.5, 6.5, 6.5}),
      body("payload", 4, payload_kg, {0, 0, 0}, {0, 0, 0}),
  };
  m.gravity_m_s2 = Eigen::Vector3d(0, 0, -9.81);
  m.task_from_base << 1, 0, 0, 0, 0, 1, 0, 1, 0;
  return m;
}

// Planar 2R arm in a vertical plane: z0 horizontal, gravity along -y0. Thin rods (no inertia
// about their own axis) and a point mass at the tip.
inline CraneModel planar_2r() {
  CraneModel m;
  m.name = "planar 2R";
  m.joints = {
      joint("shoulder", JointType::kRevolute, 1.0, 0.0, 0.0, 0.0, -kPi, kPi),
      joint("elbow", JointType::kRevolute, 0.8, 0.0, 0.0, 0.0, -2.6, 2.6),
  };
  const double i1 = 20.0 * 1.0 * 1.0 / 12.0;
  const double i2 = 12.0 * 0.8 * 0.8 / 12.0;
  m.bodies = {
      body("link 1", 1, 20, {-0.5, 0, 0}, {0, i1, i1}),
      body("link 2", 2, 12, {-0.4, 0, 0}, {0, i2, i2}),
      body("tip mass", 2, 5, {0, 0, 0}, {0, 0, 0}),
  };
  m.gravity_m_s2 = Eigen::Vector3d(0, -9.81, 0);
  return m;
}

// ---------------------------------------------------------------------------------------------
// Independent reference: recursive Newton-Euler in base-frame coordinates, written from scratch
// (own DH transform, per-body wrenches, no merging of bodies).

struct Frame {
  Eigen::Matrix3d r;
  Eigen::Vector3d p;
};

inline Frame dh(const DhJoint& j, double q) {
  const double theta = j.theta_rad + (j.type == JointType::kRevolute ? q : 0.0);
  const double d = j.d_m + (j.type == JointType::kPrismatic ? q : 0.0);
  // Rot_z(theta) Trans_z(d) Trans_x(a) Rot_x(alpha)
  const Eigen::Matrix3d rz = Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d rx =
      Eigen::AngleAxisd(j.alpha_rad, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return {rz * rx, Eigen::Vector3d(0, 0, d) + rz * Eigen::Vector3d(j.a_m, 0, 0)};
}

// tau = RNEA(q, qdot, qddot) with the given gravity (base frame).
inline JointVector rnea(const CraneModel& m, const JointVector& q, const JointVector& qd,
                        const JointVector& qdd, const Eigen::Vector3d& gravity) {
  const int n = m.dof();
  std::vector<Eigen::Matrix3d> r(n + 1);
  std::vector<Eigen::Vector3d> o(n + 1), w(n + 1), wd(n + 1), a(n + 1);
  r[0].setIdentity();
  o[0].setZero();
  w[0].setZero();
  wd[0].setZero();
  a[0] = -gravity;  // a fictitious upward base acceleration gives the gravity loads
  for (int i = 1; i <= n; ++i) {
    const DhJoint& j = m.joints[i - 1];
    const Frame t = dh(j, q[i - 1]);
    r[i] = r[i - 1] * t.r;
    o[i] = o[i - 1] + r[i - 1] * t.p;
    const Eigen::Vector3d z = r[i - 1].col(2);
    const Eigen::Vector3d link = o[i] - o[i - 1];
    if (j.type == JointType::kRevolute) {
      w[i] = w[i - 1] + z * qd[i - 1];
      wd[i] = wd[i - 1] + z * qdd[i - 1] + w[i - 1].cross(z * qd[i - 1]);
      a[i] = a[i - 1] + wd[i].cross(link) + w[i].cross(w[i].cross(link));
    } else {
      w[i] = w[i - 1];
      wd[i] = wd[i - 1];
      a[i] = a[i - 1] + wd[i].cross(link) + w[i].cross(w[i].cross(link)) +
             2.0 * w[i].cross(z * qd[i - 1]) + z * qdd[i - 1];
    }
  }
  // Inertial wrench of each frame's bodies: force, and moment about the frame origin.
  std::vector<Eigen::Vector3d> force(n + 1, Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> moment(n + 1, Eigen::Vector3d::Zero());
  for (const Body& b : m.bodies) {
    const int i = b.frame;
    const Eigen::Vector3d c = r[i] * b.com_m;
    const Eigen::Vector3d ac = a[i] + wd[i].cross(c) + w[i].cross(w[i].cross(c));
    const Eigen::Matrix3d inertia = r[i] * b.inertia_diag_kgm2.asDiagonal() * r[i].transpose();
    const Eigen::Vector3d f = b.mass_kg * ac;
    force[i] += f;
    moment[i] += inertia * wd[i] + w[i].cross(inertia * w[i]) + c.cross(f);
  }
  // Backward pass: f = force on the subtree i..n, n_o = its moment about o_i.
  JointVector tau(n);
  Eigen::Vector3d f_next = Eigen::Vector3d::Zero(), n_next = Eigen::Vector3d::Zero();
  for (int i = n; i >= 1; --i) {
    const Eigen::Vector3d f = force[i] + f_next;
    const Eigen::Vector3d n_o =
        moment[i] + n_next +
        (i < n ? Eigen::Vector3d((o[i + 1] - o[i]).cross(f_next)) : Eigen::Vector3d::Zero());
    const Eigen::Vector3d z = r[i - 1].col(2);
    if (m.joints[i - 1].type == JointType::kRevolute) {
      tau[i - 1] = z.dot(n_o + (o[i] - o[i - 1]).cross(f));  // moment about the axis at o_{i-1}
    } else {
      tau[i - 1] = z.dot(f);
    }
    f_next = f;
    n_next = n_o;
  }
  return tau;
}

struct Reference {
  JointMatrix mass;
  JointVector gravity;
  JointVector coriolis;
};

inline Reference reference_terms(const CraneModel& m, const JointVector& q, const JointVector& qd) {
  const int n = m.dof();
  const JointVector zero = JointVector::Zero(n);
  const Eigen::Vector3d no_gravity = Eigen::Vector3d::Zero();
  Reference ref;
  ref.mass.resize(n, n);
  for (int j = 0; j < n; ++j) {
    ref.mass.col(j) = rnea(m, q, zero, JointVector::Unit(n, j), no_gravity);
  }
  ref.gravity = rnea(m, q, zero, zero, m.gravity_m_s2);
  ref.coriolis = rnea(m, q, qd, zero, no_gravity);  // = RNEA(q,qd,0) - g, without cancellation
  return ref;
}

// ---------------------------------------------------------------------------------------------
// Sampling

inline JointVector random_q(const CraneModel& m, std::mt19937& rng) {
  JointVector q(m.dof());
  for (int i = 0; i < m.dof(); ++i) {
    std::uniform_real_distribution<double> u(m.joints[i].q_min, m.joints[i].q_max);
    q[i] = u(rng);
  }
  return q;
}

// Joint rates up to `scale` rad/s on hinges and scale/2 m/s on sliders.
inline JointVector random_qdot(const CraneModel& m, std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  JointVector qd(m.dof());
  for (int i = 0; i < m.dof(); ++i) {
    qd[i] = u(rng) * (m.joints[i].type == JointType::kRevolute ? scale : 0.5 * scale);
  }
  return qd;
}

inline double relative_error(const Eigen::MatrixXd& value, const Eigen::MatrixXd& reference) {
  return (value - reference).norm() / reference.norm();
}

}  // namespace craneassist::test
