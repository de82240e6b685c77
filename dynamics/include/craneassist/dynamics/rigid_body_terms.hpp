// Joint-space rigid-body dynamics terms of the crane, probed from its ODE model.
//
// Convention: tau = H(q) qddot + C(q,qdot) qdot + g(q) (+ tau_ext), as in Hulttinen & Mattila,
// "Real-time trajectory scaling algorithm for hydraulic manipulators subject to limited on-board
// power" (algorithms.md section 3). g is the effort that holds the crane still against gravity.
//
// Method. The probe owns a private ODE world (ERP = 0, CFM = 0, no end stops) holding the same
// OdeCrane the simulator steps. dWorldStep solves the joint constraints at velocity level,
// J(q) v+ = 0 with v+ = v + dt M^-1 (f + J^T lambda). From rest (v = 0) that is exactly the
// constrained acceleration, v+ / dt = qddot, whatever dt is: no Jdot v term exists at rest, the
// gyroscopic term w x I w is zero, and with CFM = 0 and ERP = 0 there is no softening or drift
// correction. So:
//   - gravity off, unit effort e_j:   qddot = H^-1 e_j         (n steps: H^-1, inverted to H)
//   - gravity on, zero effort:        qddot = -H^-1 g          (1 step: g = -H qddot)
// A single step cannot see Coriolis/centripetal terms (they are O(dt) in v+ from a moving state
// and mixed with the first-order constraint linearisation), so C(q,qdot) qdot comes from the
// Christoffel symbols of H: c_i = sum_jk (dH_ij/dq_k - 1/2 dH_jk/dq_i) qdot_j qdot_k, with dH/dq_k
// by central differences of the probed H. H does not depend on q_1 (the first joint moves the
// whole crane rigidly about/along the fixed base axis, which leaves the kinetic energy unchanged),
// so dH/dq_1 = 0 is not probed.
//
// Cost: n + 1 ODE steps for H and g, plus 2 (n - 1) n steps for C qdot when qdot != 0 (29 steps
// for the 4-joint crane). No heap allocation after construction except what ODE itself does
// (see rigid_body_terms.cpp). One instance per thread; instances in different threads may run
// in parallel (each world has its own ODE threading implementation).
#pragma once

#include <ode/ode.h>

#include <Eigen/Cholesky>
#include <memory>

#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

class OdeCrane;

struct DynamicsTerms {
  JointMatrix mass;      // H(q)
  JointVector coriolis;  // C(q, qdot) qdot
  JointVector gravity;   // g(q)
};

class RigidBodyTerms {
 public:
  // Builds its own ODE world and OdeCrane from `model` (copied) and runs a warm-up probe so that
  // ODE's step memory is allocated here, not in the control cycle.
  explicit RigidBodyTerms(const CraneModel& model);
  ~RigidBodyTerms();
  RigidBodyTerms(const RigidBodyTerms&) = delete;
  RigidBodyTerms& operator=(const RigidBodyTerms&) = delete;

  // All three terms; skips the Coriolis work when qdot is exactly zero.
  void compute(const JointVector& q, const JointVector& qdot, DynamicsTerms& out);
  void mass_matrix(const JointVector& q, JointMatrix& mass);
  void gravity(const JointVector& q, JointVector& gravity);
  void coriolis(const JointVector& q, const JointVector& qdot, JointVector& coriolis);

  int dof() const { return n_; }

  // Any dt gives the same result from rest; this one keeps the step's position update small.
  static constexpr double kProbeStepS = 1e-3;
  // Central-difference step for dH/dq (rad or m). The probed H is accurate to about 2e-13
  // relative, so the truncation error (h^2/6 H''') and the rounding error (2e-13 |H| / h) balance
  // near h = 1e-4: about 2e-8 relative error in C qdot on the K70M (1e-6 at h = 1e-3, 2e-7 at
  // h = 1e-5).
  static constexpr double kDifferenceStep = 1e-4;

 private:
  // qddot after one step from (q, 0) with the given joint effort, gravity on or off.
  void step_from_rest(const JointVector& q, const JointVector& effort, bool with_gravity,
                      JointVector& qddot);
  // H^-1 by n unit-effort probes, then H.
  void probe_mass_matrix(const JointVector& q, JointMatrix& mass);
  // -H^-1 g by one gravity probe.
  void probe_gravity_acceleration(const JointVector& q, JointVector& qddot);

  void release();

  int n_ = 0;
  Eigen::Vector3d gravity_m_s2_;
  dWorldID world_ = nullptr;
  dThreadingImplementationID threading_ = nullptr;  // this world's own (see the constructor)
  std::unique_ptr<OdeCrane> crane_;

  // Preallocated work space (bounded-size Eigen types live inline: no heap).
  JointVector zero_, effort_, qddot_, q_work_, hdot_qdot_, d_qdot_;
  JointMatrix inverse_mass_, mass_work_, mass_plus_, mass_minus_, identity_;
  Eigen::LLT<JointMatrix> llt_;  // factor of H^-1, stored inline
};

}  // namespace craneassist::dynamics
