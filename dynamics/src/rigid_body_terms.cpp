#include "craneassist/dynamics/rigid_body_terms.hpp"

#include <stdexcept>

#include "craneassist/dynamics/ode_crane.hpp"

// Allocation. dWorldStep takes its working memory (island lists, constraint Jacobian, the LCP
// matrix and its factorisation) from a per-world arena that ODE keeps between steps and only
// grows (dWorldSetStepMemoryReservationPolicy; by default at least 64 KiB, 1.2x what a step
// needs). The constructor's warm-up probe sizes it for this crane, and every later probe step has
// the same bodies, joints and constraint rows (no end stops, no contacts), so compute() does no
// heap allocation. What ODE still does per step: it walks the world's body and joint lists to
// build the island, writes into the arena, and schedules the step's stages as jobs on the world's
// self-threaded implementation (run inline on the calling thread; no threads, and its job pool is
// also reused after the warm-up).

namespace craneassist::dynamics {

namespace {

JointVector mid_range(const CraneModel& model) {
  JointVector q = JointVector::Zero(model.dof());
  for (int i = 0; i < model.dof(); ++i) {
    const DhJoint& j = model.joints[i];
    if (j.q_max > j.q_min) q[i] = 0.5 * (j.q_min + j.q_max);
  }
  return q;
}

}  // namespace

RigidBodyTerms::RigidBodyTerms(const CraneModel& model)
    : n_(model.dof()), gravity_m_s2_(model.gravity_m_s2) {
  ensure_ode_initialized();
  world_ = dWorldCreate();
  // A world without its own threading implementation steps with one process-wide default
  // instance, and two worlds stepped in parallel threads then abort inside ODE ("assertion
  // current_job->m_dependencies_count != 0 failed in ReleaseAJob"). Give this world its own.
  threading_ = dThreadingAllocateSelfThreadedImplementation();
  if (threading_ == nullptr) {
    dWorldDestroy(world_);
    throw std::runtime_error("RigidBodyTerms: cannot allocate an ODE threading implementation");
  }
  dWorldSetStepThreadingImplementation(world_, dThreadingImplementationGetFunctions(threading_),
                                       threading_);
  // The probe's own settings, independent of the simulator's: exact constraints (CFM = 0) and no
  // position-error feedback (ERP = 0), so a step from rest yields the exact acceleration.
  dWorldSetERP(world_, 0.0);
  dWorldSetCFM(world_, 0.0);
  dWorldSetGravity(world_, 0.0, 0.0, 0.0);
  dWorldSetStepMemoryReservationPolicy(world_, nullptr);  // ODE's defaults, stated explicitly
  try {
    const JointVector q0 = mid_range(model);
    crane_ = std::make_unique<OdeCrane>(model, world_, q0);
    zero_ = JointVector::Zero(n_);
    effort_ = JointVector::Zero(n_);
    qddot_ = JointVector::Zero(n_);
    q_work_ = JointVector::Zero(n_);
    hdot_qdot_ = JointVector::Zero(n_);
    d_qdot_ = JointVector::Zero(n_);
    inverse_mass_ = JointMatrix::Zero(n_, n_);
    mass_work_ = JointMatrix::Zero(n_, n_);
    mass_plus_ = JointMatrix::Zero(n_, n_);
    mass_minus_ = JointMatrix::Zero(n_, n_);
    identity_ = JointMatrix::Identity(n_, n_);
    // Warm-up: the first dWorldStep allocates ODE's step arena.
    probe_mass_matrix(q0, mass_plus_);
    probe_gravity_acceleration(q0, qddot_);
  } catch (...) {
    release();
    throw;
  }
}

RigidBodyTerms::~RigidBodyTerms() {
  release();
}

void RigidBodyTerms::release() {
  crane_.reset();  // its bodies and joints belong to world_
  dWorldSetStepThreadingImplementation(world_, nullptr, nullptr);
  dWorldDestroy(world_);
  dThreadingFreeImplementation(threading_);
}

void RigidBodyTerms::step_from_rest(const JointVector& q, const JointVector& effort,
                                    bool with_gravity, JointVector& qddot) {
  crane_->set_state(q, zero_);
  for (int i = 1; i <= n_; ++i) {
    dBodySetForce(crane_->body(i), 0.0, 0.0, 0.0);
    dBodySetTorque(crane_->body(i), 0.0, 0.0, 0.0);
  }
  if (with_gravity) {
    dWorldSetGravity(world_, gravity_m_s2_.x(), gravity_m_s2_.y(), gravity_m_s2_.z());
  } else {
    dWorldSetGravity(world_, 0.0, 0.0, 0.0);
  }
  crane_->add_joint_efforts(effort);
  if (dWorldStep(world_, kProbeStepS) == 0) {
    throw std::runtime_error("RigidBodyTerms: dWorldStep failed (out of memory)");
  }
  // Rates with the pre-step geometry: exact, see OdeCrane::read_rates_at_set_pose.
  crane_->read_rates_at_set_pose(qddot);
  qddot /= kProbeStepS;
}

void RigidBodyTerms::probe_mass_matrix(const JointVector& q, JointMatrix& mass) {
  effort_.setZero();
  for (int j = 0; j < n_; ++j) {
    effort_[j] = 1.0;
    step_from_rest(q, effort_, false, qddot_);
    inverse_mass_.col(j) = qddot_;
    effort_[j] = 0.0;
  }
  // Symmetric in exact arithmetic; average away the rounding before factorising.
  llt_.compute(0.5 * (inverse_mass_ + inverse_mass_.transpose()));
  if (llt_.info() != Eigen::Success) {
    throw std::runtime_error("RigidBodyTerms: probed inverse mass matrix is not positive definite");
  }
  mass = identity_;
  llt_.solveInPlace(mass);
  mass = 0.5 * (mass + mass.transpose()).eval();
}

void RigidBodyTerms::probe_gravity_acceleration(const JointVector& q, JointVector& qddot) {
  step_from_rest(q, zero_, true, qddot);
}

void RigidBodyTerms::mass_matrix(const JointVector& q, JointMatrix& mass) {
  probe_mass_matrix(q, mass);
}

void RigidBodyTerms::gravity(const JointVector& q, JointVector& gravity) {
  probe_mass_matrix(q, mass_plus_);
  probe_gravity_acceleration(q, qddot_);
  gravity.noalias() = -mass_plus_ * qddot_;
}

void RigidBodyTerms::coriolis(const JointVector& q, const JointVector& qdot,
                              JointVector& coriolis) {
  coriolis.setZero(n_);
  if (qdot.squaredNorm() == 0.0) return;
  // c = (sum_k qdot_k dH/dq_k) qdot - 1/2 [qdot^T dH/dq_i qdot]_i. dH/dq_1 = 0 (header).
  hdot_qdot_.setZero(n_);
  for (int k = 1; k < n_; ++k) {
    q_work_ = q;
    q_work_[k] = q[k] + kDifferenceStep;
    probe_mass_matrix(q_work_, mass_plus_);
    q_work_[k] = q[k] - kDifferenceStep;
    probe_mass_matrix(q_work_, mass_minus_);
    mass_work_ = (mass_plus_ - mass_minus_) / (2.0 * kDifferenceStep);  // dH/dq_k
    d_qdot_.noalias() = mass_work_ * qdot;
    hdot_qdot_ += qdot[k] * d_qdot_;
    coriolis[k] -= 0.5 * qdot.dot(d_qdot_);
  }
  coriolis += hdot_qdot_;
}

void RigidBodyTerms::compute(const JointVector& q, const JointVector& qdot, DynamicsTerms& out) {
  probe_mass_matrix(q, out.mass);
  probe_gravity_acceleration(q, qddot_);
  out.gravity.noalias() = -out.mass * qddot_;
  coriolis(q, qdot, out.coriolis);
}

}  // namespace craneassist::dynamics
