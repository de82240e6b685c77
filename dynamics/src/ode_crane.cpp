#include "craneassist/dynamics/ode_crane.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace craneassist::dynamics {

namespace {

struct MergedMass {
  double mass = 0.0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();      // frame-i axes, from the frame origin
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about `com`, frame-i axes
};

// Merges every model body on `frame` into one rigid body (parallel-axis theorem).
MergedMass merge_bodies(const CraneModel& model, int frame) {
  MergedMass merged;
  Eigen::Vector3d first_moment = Eigen::Vector3d::Zero();
  for (const Body& b : model.bodies) {
    if (b.frame != frame) continue;
    merged.mass += b.mass_kg;
    first_moment += b.mass_kg * b.com_m;
  }
  if (merged.mass <= 0.0) {
    // No mass on this frame (e.g. a massless intermediate DH frame). ODE needs a positive mass
    // and a positive-definite inertia, so give the body a negligible placeholder at the frame
    // origin: 1e-6 kg with 1e-6 kg m^2 inertia (a 1 m radius of gyration). It adds a 1e-6 kg
    // error to H and makes ODE's constraint matrix badly scaled, so real models should not rely
    // on it.
    merged.mass = OdeCrane::kEmptyFrameMassKg;
    merged.inertia = OdeCrane::kEmptyFrameMassKg * Eigen::Matrix3d::Identity();
    return merged;
  }
  merged.com = first_moment / merged.mass;
  for (const Body& b : model.bodies) {
    if (b.frame != frame) continue;
    const Eigen::Vector3d d = b.com_m - merged.com;
    merged.inertia += b.inertia_diag_kgm2.asDiagonal();
    merged.inertia +=
        b.mass_kg * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  }
  // ODE inverts the body inertia (and silently substitutes the identity when that fails), so it
  // must be positive definite. Rods and point masses are not: a thin rod has no inertia about
  // its own axis. Raise only the deficient principal moments to a small floor. A deficient axis
  // is one about which the body's mass distribution has no extent, and as long as the joints
  // never turn the body about it (a rod in a planar arm) the floor has no effect on H at all.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(merged.inertia);
  const Eigen::Vector3d lambda = eig.eigenvalues();  // ascending
  const double floor = 1e-6 * std::max(lambda[2], merged.mass * 1.0 /* m^2 */);
  if (lambda[0] < floor) {
    merged.inertia =
        eig.eigenvectors() * lambda.cwiseMax(floor).asDiagonal() * eig.eigenvectors().transpose();
    merged.inertia = 0.5 * (merged.inertia + merged.inertia.transpose()).eval();
  }
  return merged;
}

void to_ode(const Eigen::Matrix3d& r, dMatrix3 out) {
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) out[4 * row + col] = r(row, col);
    out[4 * row + 3] = 0.0;
  }
}

Eigen::Vector3d vec(const dReal* v) {
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

bool has_range(const DhJoint& j) {
  return j.q_max > j.q_min;
}

}  // namespace

void ensure_ode_initialized() {
  // dInitODE2 must run once per process before any other ODE call; a function-local static is
  // initialised exactly once even when several threads get here together. ODE also keeps
  // per-thread data when it is built with thread-local storage; Debian's build is not (its
  // dGetConfiguration() lacks ODE_EXT_ou) and then the call is a cheap no-op, but it costs
  // nothing to be correct for builds that are.
  static const bool process_ok = dInitODE2(0) != 0;
  // dAllocateMaskAll is the enum value ~0 (an int, -1): all bits of the unsigned flag word.
  thread_local const bool thread_ok =
      dAllocateODEDataForThread(static_cast<unsigned>(dAllocateMaskAll)) != 0;
  if (!process_ok || !thread_ok) throw std::runtime_error("ODE initialisation failed");
}

OdeCrane::OdeCrane(const CraneModel& model, dWorldID world, const JointVector& q_initial)
    : model_(model), n_(model.dof()) {
  if (n_ < 1 || n_ > kMaxJoints) {
    throw std::invalid_argument("OdeCrane: the model needs 1.." + std::to_string(kMaxJoints) +
                                " joints");
  }
  if (q_initial.size() != n_) throw std::invalid_argument("OdeCrane: q_initial has wrong size");
  for (const Body& b : model_.bodies) {
    if (b.frame < 1 || b.frame > n_) {
      throw std::invalid_argument("OdeCrane: body '" + b.name + "' is on frame " +
                                  std::to_string(b.frame) + ", outside 1.." + std::to_string(n_));
    }
    if (b.mass_kg < 0.0) throw std::invalid_argument("OdeCrane: body '" + b.name + "' mass < 0");
  }
  ensure_ode_initialized();

  // Reference pose: joints in mid-range (see the header for why), else at q_initial.
  q_ref_ = q_initial;
  for (int i = 0; i < n_; ++i) {
    const DhJoint& j = model_.joints[i];
    if (has_range(j)) q_ref_[i] = 0.5 * (j.q_min + j.q_max);
  }
  forward_kinematics(model_, kin_, q_ref_);

  com_local_[0].setZero();
  for (int i = 1; i <= n_; ++i) {
    const MergedMass merged = merge_bodies(model_, i);
    com_local_[i] = merged.com;
    mass_[i] = merged.mass;
    dMass m;
    // ODE requires the mass centred at the body position: inertia about the centre of mass.
    dMassSetParameters(&m, merged.mass, 0.0, 0.0, 0.0, merged.inertia(0, 0), merged.inertia(1, 1),
                       merged.inertia(2, 2), merged.inertia(0, 1), merged.inertia(0, 2),
                       merged.inertia(1, 2));
    bodies_[i] = dBodyCreate(world);
    dBodySetMass(bodies_[i], &m);
    const Eigen::Isometry3d& frame = kin_.frames[i];
    const Eigen::Vector3d p = frame * merged.com;
    dMatrix3 r;
    to_ode(frame.linear(), r);
    dBodySetPosition(bodies_[i], p.x(), p.y(), p.z());
    dBodySetRotation(bodies_[i], r);
  }

  for (int i = 1; i <= n_; ++i) {
    const Eigen::Vector3d anchor = kin_.frames[i - 1].translation();
    const Eigen::Vector3d axis = kin_.frames[i - 1].linear().col(2);
    if (model_.joints[i - 1].type == JointType::kRevolute) {
      joints_[i] = dJointCreateHinge(world, nullptr);
      dJointAttach(joints_[i], bodies_[i], bodies_[i - 1]);
      dJointSetHingeAnchor(joints_[i], anchor.x(), anchor.y(), anchor.z());
      dJointSetHingeAxis(joints_[i], axis.x(), axis.y(), axis.z());  // also sets angle zero
    } else {
      joints_[i] = dJointCreateSlider(world, nullptr);
      dJointAttach(joints_[i], bodies_[i], bodies_[i - 1]);
      dJointSetSliderAxis(joints_[i], axis.x(), axis.y(), axis.z());  // also sets position zero
    }
  }

  set_state(q_initial, JointVector::Zero(n_));
}

OdeCrane::~OdeCrane() {
  for (int i = n_; i >= 1; --i) {
    if (joints_[i] != nullptr) dJointDestroy(joints_[i]);
  }
  for (int i = n_; i >= 1; --i) {
    if (bodies_[i] != nullptr) dBodyDestroy(bodies_[i]);
  }
}

void OdeCrane::set_state(const JointVector& q, const JointVector& qdot) {
  forward_kinematics(model_, kin_, q);
  // Angular velocity of each frame and velocity of each frame origin, base to tip (the same
  // recursion as tip_jacobian_dot in kinematics.cpp).
  kin_.omega[0].setZero();
  kin_.origin_velocity[0].setZero();
  for (int i = 1; i <= n_; ++i) {
    const Eigen::Vector3d z = kin_.frames[i - 1].linear().col(2);
    const bool revolute = model_.joints[i - 1].type == JointType::kRevolute;
    kin_.omega[i] = kin_.omega[i - 1];
    kin_.origin_velocity[i] = kin_.origin_velocity[i - 1];
    if (revolute) {
      kin_.omega[i] += z * qdot[i - 1];
    } else {
      kin_.origin_velocity[i] += z * qdot[i - 1];
    }
    kin_.origin_velocity[i] +=
        kin_.omega[i].cross(kin_.frames[i].translation() - kin_.frames[i - 1].translation());
  }
  for (int i = 1; i <= n_; ++i) {
    const Eigen::Isometry3d& frame = kin_.frames[i];
    const Eigen::Vector3d arm = frame.linear() * com_local_[i];
    const Eigen::Vector3d p = frame.translation() + arm;
    const Eigen::Vector3d v = kin_.origin_velocity[i] + kin_.omega[i].cross(arm);
    const Eigen::Vector3d& w = kin_.omega[i];
    dMatrix3 r;
    to_ode(frame.linear(), r);
    dBodySetPosition(bodies_[i], p.x(), p.y(), p.z());
    dBodySetRotation(bodies_[i], r);
    dBodySetLinearVel(bodies_[i], v.x(), v.y(), v.z());
    dBodySetAngularVel(bodies_[i], w.x(), w.y(), w.z());
  }
}

void OdeCrane::read_state(JointVector& q, JointVector& qdot) const {
  q.resize(n_);
  qdot.resize(n_);
  for (int i = 1; i <= n_; ++i) {
    const dJointID j = joints_[i];
    if (model_.joints[i - 1].type == JointType::kRevolute) {
      q[i - 1] = q_ref_[i - 1] + dJointGetHingeAngle(j);
      qdot[i - 1] = dJointGetHingeAngleRate(j);  // axis . (w_i - w_{i-1}): exact
      continue;
    }
    q[i - 1] = q_ref_[i - 1] + dJointGetSliderPosition(j);  // exact for any rotation
    dVector3 axis;
    dJointGetSliderAxis(j, axis);
    const Eigen::Vector3d z = vec(axis);
    Eigen::Vector3d relative = vec(dBodyGetLinearVel(bodies_[i]));
    if (bodies_[i - 1] != nullptr) {
      // Velocity of the child's centre of mass relative to the parent's frame: subtract the
      // velocity of the parent-fixed point that coincides with it.
      const Eigen::Vector3d arm =
          vec(dBodyGetPosition(bodies_[i])) - vec(dBodyGetPosition(bodies_[i - 1]));
      relative -= vec(dBodyGetLinearVel(bodies_[i - 1])) +
                  vec(dBodyGetAngularVel(bodies_[i - 1])).cross(arm);
    }
    qdot[i - 1] = z.dot(relative);
  }
}

void OdeCrane::read_rates_at_set_pose(JointVector& qdot) const {
  qdot.resize(n_);
  Eigen::Vector3d w_parent = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_parent = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_parent = Eigen::Vector3d::Zero();
  for (int i = 1; i <= n_; ++i) {
    const Eigen::Vector3d z = kin_.frames[i - 1].linear().col(2);
    const Eigen::Vector3d w = vec(dBodyGetAngularVel(bodies_[i]));
    const Eigen::Vector3d v = vec(dBodyGetLinearVel(bodies_[i]));
    const Eigen::Vector3d p = kin_.frames[i] * com_local_[i];
    if (model_.joints[i - 1].type == JointType::kRevolute) {
      qdot[i - 1] = z.dot(w - w_parent);
    } else {
      qdot[i - 1] = z.dot(v - v_parent - w_parent.cross(p - p_parent));
    }
    w_parent = w;
    v_parent = v;
    p_parent = p;
  }
}

void OdeCrane::add_joint_efforts(const JointVector& tau) {
  for (int i = 1; i <= n_; ++i) {
    if (model_.joints[i - 1].type == JointType::kRevolute) {
      dJointAddHingeTorque(joints_[i], tau[i - 1]);
    } else {
      // Force +tau on the child and -tau on the parent, each at its centre of mass, plus ODE's
      // "linear torque decoupling" torques that cancel the couple of the two offset forces; the
      // result does work only on the slider coordinate, as a generalized force must.
      dJointAddSliderForce(joints_[i], tau[i - 1]);
    }
  }
}

void OdeCrane::set_payload_mass(double mass_kg) noexcept {
  if (!(mass_kg >= 0.0)) return;
  for (Body& b : model_.bodies) {
    if (!is_payload(b)) continue;
    b.mass_kg = mass_kg;
    const int i = b.frame;
    const MergedMass merged = merge_bodies(model_, i);
    com_local_[static_cast<size_t>(i)] = merged.com;
    mass_[static_cast<size_t>(i)] = merged.mass;
    dMass m;
    dMassSetParameters(&m, merged.mass, 0.0, 0.0, 0.0, merged.inertia(0, 0), merged.inertia(1, 1),
                       merged.inertia(2, 2), merged.inertia(0, 1), merged.inertia(0, 2),
                       merged.inertia(1, 2));
    dBodySetMass(bodies_[static_cast<size_t>(i)], &m);
    return;
  }
}

void OdeCrane::enable_end_stops(bool on) {
  constexpr double kPi = std::numbers::pi;
  for (int i = 1; i <= n_; ++i) {
    const DhJoint& j = model_.joints[i - 1];
    double lo = -dInfinity;
    double hi = dInfinity;
    if (on && has_range(j)) {
      lo = j.q_min - q_ref_[i - 1];
      hi = j.q_max - q_ref_[i - 1];
      if (j.type == JointType::kRevolute) {
        lo = std::max(lo, -kPi + kHingeStopMargin);
        hi = std::min(hi, kPi - kHingeStopMargin);
      }
    }
    if (j.type == JointType::kRevolute) {
      dJointSetHingeParam(joints_[i], dParamLoStop, lo);
      dJointSetHingeParam(joints_[i], dParamHiStop, hi);
    } else {
      dJointSetSliderParam(joints_[i], dParamLoStop, lo);
      dJointSetSliderParam(joints_[i], dParamHiStop, hi);
    }
  }
}

}  // namespace craneassist::dynamics
