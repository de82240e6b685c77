#include "craneassist/dynamics/rigid_body_terms.hpp"

#include <ode/ode.h>

#include <stdexcept>

#include "craneassist/dynamics/kinematics.hpp"
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

Eigen::Vector3d vec(const dReal* v) {
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

JointVector mid_range(const CraneModel& model) {
  JointVector q = JointVector::Zero(model.dof());
  for (int i = 0; i < model.dof(); ++i) {
    const DhJoint& j = model.joints[i];
    if (j.q_max > j.q_min) q[i] = 0.5 * (j.q_min + j.q_max);
  }
  return q;
}

}  // namespace

struct RigidBodyTerms::Impl {
  dWorldID world = nullptr;
  dThreadingImplementationID threading = nullptr;  // this world's own (see below)
  std::unique_ptr<OdeCrane> crane;
  std::array<dJointFeedback, kMaxJoints + 1> feedback{};  // 1..n, registered with ODE

  Impl() {
    ensure_ode_initialized();
    world = dWorldCreate();
    // A world without its own threading implementation steps with one process-wide default
    // instance, and two worlds stepped in parallel threads then abort inside ODE ("assertion
    // current_job->m_dependencies_count != 0 failed in ReleaseAJob"). Give this world its own.
    threading = dThreadingAllocateSelfThreadedImplementation();
    if (threading == nullptr) {
      dWorldDestroy(world);
      throw std::runtime_error("RigidBodyTerms: cannot allocate an ODE threading implementation");
    }
    dWorldSetStepThreadingImplementation(world, dThreadingImplementationGetFunctions(threading),
                                         threading);
  }
  ~Impl() {
    crane.reset();  // its bodies and joints belong to world
    dWorldSetStepThreadingImplementation(world, nullptr, nullptr);
    dWorldDestroy(world);
    dThreadingFreeImplementation(threading);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
};

void RigidBodyTerms::set_payload_mass(double mass_kg) noexcept {
  if (!(mass_kg >= 0.0) || mass_kg == payload_mass_kg_) return;
  OdeCrane& crane = *impl_->crane;
  crane.set_payload_mass(mass_kg);
  payload_mass_kg_ = mass_kg;
  for (int i = 1; i <= n_; ++i) {
    dMass mass;
    dBodyGetMass(crane.body(i), &mass);
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) inertia_body_[i](row, col) = mass.I[4 * row + col];
    }
  }
}

RigidBodyTerms::RigidBodyTerms(const CraneModel& model)
    : impl_(std::make_unique<Impl>()),
      n_(model.dof()),
      gravity_m_s2_(model.gravity_m_s2),
      payload_mass_kg_(payload_mass_kg(model)) {
  // impl_ is a member: should anything below throw, its destructor releases the world.
  dWorldID world = impl_->world;
  // The probe's own settings, independent of the simulator's: exact constraints (CFM = 0) and no
  // position-error feedback (ERP = 0), so a step from rest yields the exact acceleration.
  dWorldSetERP(world, 0.0);
  dWorldSetCFM(world, 0.0);
  dWorldSetGravity(world, 0.0, 0.0, 0.0);
  dWorldSetStepMemoryReservationPolicy(world, nullptr);  // ODE's defaults, stated explicitly
  const JointVector q0 = mid_range(model);
  impl_->crane = std::make_unique<OdeCrane>(model, world, q0);
  OdeCrane& crane = *impl_->crane;
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
  path_acc_ = JointVector::Zero(n_);
  path_qdot_ = JointVector::Zero(n_);
  for (int i = 1; i <= n_; ++i) {
    dMass mass;
    dBodyGetMass(crane.body(i), &mass);  // inertia in body axes, about the centre of mass
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) inertia_body_[i](row, col) = mass.I[4 * row + col];
    }
    // Motor reactions of path_terms(); ODE fills these on every step.
    dJointSetFeedback(crane.joint(i), &impl_->feedback[i]);
    // Rigid motor rows (the motor CFM defaults to the world's CFM at joint creation; say it).
    set_motor_param(i, dParamCFM, 0.0);
  }
  // Warm-up: the first dWorldStep allocates ODE's step arena; the motor steps of path_terms()
  // have n more constraint rows, so size it for those too.
  probe_mass_matrix(q0, mass_plus_);
  probe_gravity_acceleration(q0, qddot_);
  PathTerms warm_up;
  const JointVector ones = JointVector::Ones(n_);
  if (!path_terms(q0, ones, ones, 1.0, warm_up)) {
    throw std::runtime_error("RigidBodyTerms: dWorldStep failed (out of memory)");
  }
}

RigidBodyTerms::~RigidBodyTerms() = default;

void RigidBodyTerms::set_gravity(bool on) noexcept {
  if (on) {
    dWorldSetGravity(impl_->world, gravity_m_s2_.x(), gravity_m_s2_.y(), gravity_m_s2_.z());
  } else {
    dWorldSetGravity(impl_->world, 0.0, 0.0, 0.0);
  }
}

bool RigidBodyTerms::step_world() noexcept {
  if (fail_steps_for_testing_) return false;
  return dWorldStep(impl_->world, kProbeStepS) != 0;
}

void RigidBodyTerms::step_from_rest(const JointVector& q, const JointVector& effort,
                                    bool with_gravity, JointVector& qddot) {
  OdeCrane& crane = *impl_->crane;
  rest_at(q, false);
  set_gravity(with_gravity);
  crane.add_joint_efforts(effort);
  if (!step_world()) {
    throw std::runtime_error("RigidBodyTerms: dWorldStep failed (out of memory)");
  }
  // Rates with the pre-step geometry: exact, see OdeCrane::read_rates_at_set_pose.
  crane.read_rates_at_set_pose(qddot);
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

void RigidBodyTerms::power_motors(bool on) noexcept {
  if (on == motors_on_) return;
  // dInfinity makes the motor row an unbounded (equality) row of ODE's LCP; 0 removes the row.
  const double fmax = on ? dInfinity : 0.0;
  for (int i = 1; i <= n_; ++i) set_motor_param(i, dParamFMax, fmax);
  motors_on_ = on;
}

void RigidBodyTerms::set_motor_param(int i, int param, double value) noexcept {
  const OdeCrane& crane = *impl_->crane;
  if (crane.model().joints[i - 1].type == JointType::kRevolute) {
    dJointSetHingeParam(crane.joint(i), param, value);
  } else {
    dJointSetSliderParam(crane.joint(i), param, value);
  }
}

void RigidBodyTerms::rest_at(const JointVector& q, bool motors) noexcept {
  OdeCrane& crane = *impl_->crane;
  power_motors(motors);
  crane.set_state(q, zero_);
  for (int i = 1; i <= n_; ++i) {
    dBodySetForce(crane.body(i), 0.0, 0.0, 0.0);
    dBodySetTorque(crane.body(i), 0.0, 0.0, 0.0);
  }
}

bool RigidBodyTerms::motor_step(const JointVector& q, const JointVector& qddot, bool with_gravity,
                                const JointVector* velocity_products,
                                JointVector& effort) noexcept {
  rest_at(q, true);
  for (int i = 1; i <= n_; ++i) {
    // From rest the motor row enforces rate = dParamVel after the step: dt * qddot.
    set_motor_param(i, dParamVel, kProbeStepS * qddot[i - 1]);
  }
  set_gravity(with_gravity);
  if (velocity_products != nullptr) add_velocity_product_wrenches(*velocity_products);
  if (!step_world()) return false;
  read_motor_efforts(effort);
  return true;
}

void RigidBodyTerms::add_velocity_product_wrenches(const JointVector& qdot) noexcept {
  const OdeCrane& crane = *impl_->crane;
  // Forward recursion at qddot = 0 in base-frame coordinates: w = angular velocity of frame i,
  // alpha = its angular acceleration, acc = acceleration of its origin o_i. The axis z_{i-1} is
  // fixed in frame i-1; o_i - o_{i-1} is fixed in frame i for a hinge (o_{i-1} is on its axis)
  // and grows by z_{i-1} qdot_i for a slider.
  const KinematicsData& kin = crane.kinematics();
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  Eigen::Vector3d alpha = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc = Eigen::Vector3d::Zero();
  for (int i = 1; i <= n_; ++i) {
    const Eigen::Vector3d z = kin.frames[i - 1].linear().col(2);
    const Eigen::Vector3d link = kin.frames[i].translation() - kin.frames[i - 1].translation();
    const double rate = qdot[i - 1];
    if (crane.model().joints[i - 1].type == JointType::kRevolute) {
      alpha += w.cross(z * rate);
      w += z * rate;
      acc += alpha.cross(link) + w.cross(w.cross(link));
    } else {
      acc += alpha.cross(link) + w.cross(w.cross(link)) + 2.0 * w.cross(z * rate);
    }
    const Eigen::Matrix3d& r = kin.frames[i].linear();
    const Eigen::Vector3d arm = r * crane.com_local(i);
    const Eigen::Vector3d acc_com = acc + alpha.cross(arm) + w.cross(w.cross(arm));
    const Eigen::Matrix3d inertia = r * inertia_body_[i] * r.transpose();
    const Eigen::Vector3d force = crane.mass(i) * acc_com;
    const Eigen::Vector3d torque = inertia * alpha + w.cross(inertia * w);  // about the CoM
    dBodyAddForce(crane.body(i), -force.x(), -force.y(), -force.z());
    dBodyAddTorque(crane.body(i), -torque.x(), -torque.y(), -torque.z());
  }
}

void RigidBodyTerms::read_motor_efforts(JointVector& effort) const noexcept {
  // Geometry of the set_state() pose, which is the pose ODE built the constraint rows at (the
  // step has since moved the bodies). Joint i attaches body i first, so f1, t1 act on the child.
  const OdeCrane& crane = *impl_->crane;
  const KinematicsData& kin = crane.kinematics();
  effort.resize(n_);
  for (int i = 1; i <= n_; ++i) {
    const dJointFeedback& fb = impl_->feedback[i];
    const Eigen::Vector3d z = kin.frames[i - 1].linear().col(2);
    const Eigen::Vector3d f1 = vec(fb.f1);
    if (crane.model().joints[i - 1].type == JointType::kRevolute) {
      // Moment about the hinge axis through o_{i-1} of the wrench on the child.
      const Eigen::Vector3d com = kin.frames[i] * crane.com_local(i);
      const Eigen::Vector3d arm = com - kin.frames[i - 1].translation();
      effort[i - 1] = z.dot(vec(fb.t1) + arm.cross(f1));
    } else {
      effort[i - 1] = z.dot(f1);
    }
  }
}

bool RigidBodyTerms::path_terms(const JointVector& q, const JointVector& f1, const JointVector& f2,
                                double sdot, PathTerms& out) noexcept {
  // m = H f': gravity off, no external wrenches, motors at qddot = f'.
  if (!motor_step(q, f1, false, nullptr, out.m)) return false;
  // b = H f'' sdot^2 + C(q, f' sdot) f' sdot + g.
  const double sdot2 = sdot * sdot;
  path_acc_ = f2 * sdot2;
  if (sdot == 0.0) return motor_step(q, path_acc_, true, nullptr, out.b);
  path_qdot_ = f1 * sdot;
  return motor_step(q, path_acc_, true, &path_qdot_, out.b);
}

}  // namespace craneassist::dynamics
