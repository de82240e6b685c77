// Joint-space rigid-body dynamics terms of the crane, probed from its ODE model.
//
// Convention: tau = H(q) qddot + C(q,qdot) qdot + g(q) (+ tau_ext), as in Hulttinen & Mattila,
// "Real-time trajectory scaling algorithm for hydraulic manipulators subject to limited on-board
// power" (docs/algorithms.md section 3). g is the effort that holds the crane still against
// gravity.
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
//
// Path terms (path_terms()): the per-cycle m = H f' and b = H f'' sdot^2 + C(q, f' sdot) f' sdot
// + g of the power-limited scaling, in 2 ODE steps, without forming H. See path_terms() below.
//
// Errors. A probe step fails only when ODE cannot get memory for it (dWorldStep returns 0; the
// constructor's warm-up sizes ODE's step arena, so after it this does not happen in practice).
//   - Cycle-safe: path_terms() is noexcept and allocates nothing; a failed step is its false
//     return (the scalers stop on it, ActiveLimit::kDynamicsFailed).
//   - Not cycle-safe, for tests and offline tools: the constructor, compute(), mass_matrix(),
//     gravity() and coriolis() throw std::runtime_error for a failed step (and for a probed H^-1
//     that is not positive definite).
//
// ODE stays an implementation detail: this header includes no ODE header (the world, its
// threading implementation, the OdeCrane and the joint feedback live behind Impl), and the
// dynamics target links ODE privately. The plain terms are in path_terms.hpp.
#pragma once

#include <Eigen/Cholesky>
#include <array>
#include <memory>

#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/path_terms.hpp"

namespace craneassist::dynamics {

class RigidBodyTerms {
 public:
  // Builds its own ODE world and OdeCrane from `model` (copied) and runs a warm-up probe so that
  // ODE's step memory is allocated here, not in the control cycle. Throws std::runtime_error (ODE
  // resources, a failed warm-up step) and std::invalid_argument (the model, see OdeCrane).
  explicit RigidBodyTerms(const CraneModel& model);
  ~RigidBodyTerms();
  RigidBodyTerms(const RigidBodyTerms&) = delete;
  RigidBodyTerms& operator=(const RigidBodyTerms&) = delete;

  // All three terms; skips the Coriolis work when qdot is exactly zero. These four throw
  // std::runtime_error when a probe step fails (see Errors above): not for the control cycle.
  void compute(const JointVector& q, const JointVector& qdot, DynamicsTerms& out);
  void mass_matrix(const JointVector& q, JointMatrix& mass);
  void gravity(const JointVector& q, JointVector& gravity);
  void coriolis(const JointVector& q, const JointVector& qdot, JointVector& coriolis);

  // m and b of PathTerms at q for path tangent f1 = f' (joint velocity per unit path speed), its
  // path derivative f2 = f'' and path speed sdot. No heap allocation, no exception: cycle-safe.
  // Returns false when an ODE step failed (out of memory); out is then unspecified.
  //
  // Cost: 2 ODE steps whatever sdot is (compute() takes n + 1 + 2 n (n - 1) = 29 for the K70M);
  // about 9 us on the K70M. Exact up to rounding: no finite differences, about 1e-13 relative
  // against recursive Newton-Euler (tests/dynamics/test_path_dynamics.cpp).
  //
  // Method: inverse dynamics with ODE velocity motors. Every joint gets a motor with unlimited
  // force (dParamFMax = dInfinity, motor CFM = 0) and target rate dParamVel = dt a_j. From rest
  // at q one dWorldStep makes the joint rates exactly dt a (the motor rows are equality rows of
  // the velocity-level solve described above), so the bodies take exactly the accelerations of
  // qddot = a and the motor forces are the efforts that produce them:
  //   tau = H a + g - Q    (g only with gravity on; Q = generalized force of external wrenches).
  // The motor of joint i puts equal and opposite wrenches on child and parent, so it loads joint i
  // only, and the joint's other rows are workless along its motion; so tau_i is joint i's
  // dJointFeedback (f1 at, t1 about, the centre of mass of body 1 = the child, see OdeCrane)
  // projected on the joint motion: z_{i-1} . (t1 + (com_i - o_{i-1}) x f1) for a hinge,
  // z_{i-1} . f1 for a slider.
  //   step 1: gravity off, a = f'                      -> tau = H f' = m.
  //   step 2: gravity on, a = f'' sdot^2, and on every body minus its inertial wrench for the
  //           velocity-product motion (qdot = f' sdot, qddot = 0): force -m_b acc_b at the centre
  //           of mass, torque -(I_b alpha_b + w_b x I_b w_b), with ODE's own mass and inertia of
  //           the body. Their generalized force is Q = -C(q, qdot) qdot (Newton-Euler), so
  //           tau = H f'' sdot^2 + C(q, f' sdot) f' sdot + g = b (no wrenches if sdot == 0).
  // The velocity-product accelerations (acc_b, alpha_b, w_b) are kinematics only: a forward
  // recursion over the DH frames, as for OdeCrane::set_state's velocities. A motor step from the
  // moving state cannot supply them: ODE's constraint J(q) v+ = c has no Jdot v term, so only the
  // gyroscopic part would appear. The alternative of central differences of motor-probed
  // H(q') f' (2 steps for (dH/dq . f') f', 2 per joint 2..n for grad_q f'^T H f') needs 2 n more
  // steps (10 in all for the K70M, about 50 us) and is accurate to about 2e-8 only.
  [[nodiscard]] bool path_terms(const JointVector& q, const JointVector& f1, const JointVector& f2,
                                double sdot, PathTerms& out) noexcept;

  int dof() const { return n_; }

  // The payload mass the probe uses from now on (the model's body named "payload"; the crane
  // scale's estimate in the control loop). Cycle-safe: no allocation, no exception.
  void set_payload_mass(double mass_kg) noexcept;
  double payload_mass() const noexcept { return payload_mass_kg_; }

  // Test hook, nothing else sets it: while on, every probe step fails as dWorldStep does when
  // ODE runs out of memory (the step is not taken), so tests can reach the failure paths that a
  // real machine reaches only on memory exhaustion. Off by default.
  void fail_steps_for_testing(bool fail) noexcept { fail_steps_for_testing_ = fail; }

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

  // Velocity motors on (unlimited force) or off (the state of compute()'s probes).
  void power_motors(bool on) noexcept;
  // ODE parameter `param` (dParamCFM, dParamFMax, dParamVel) of joint i's motor (1-based), hinge or
  // slider.
  void set_motor_param(int i, int param, double value) noexcept;
  // The start of every probe step: the crane at rest at q, no force or torque on its bodies, the
  // velocity motors on or off.
  void rest_at(const JointVector& q, bool motors) noexcept;
  // Motor reactions after one step from (q, 0) with motor targets qddot, gravity on or off, and,
  // when velocity_products is given, minus the velocity-product inertial wrenches at that qdot.
  // False when the step failed (effort is then left as it was).
  [[nodiscard]] bool motor_step(const JointVector& q, const JointVector& qddot, bool with_gravity,
                                const JointVector* velocity_products, JointVector& effort) noexcept;
  // Adds minus the inertial wrench of the qddot = 0 motion at joint rates qdot to every body
  // (uses the frames of the last set_state()).
  void add_velocity_product_wrenches(const JointVector& qdot) noexcept;
  // Generalized motor efforts from the joint feedback of the last step.
  void read_motor_efforts(JointVector& effort) const noexcept;
  // The probe world's gravity: the model's, or none.
  void set_gravity(bool on) noexcept;
  // One dWorldStep of the probe world; false when it failed (or the test hook is on).
  [[nodiscard]] bool step_world() noexcept;

  // The ODE side: the probe world, its own threading implementation, the OdeCrane in it and the
  // joint feedback registered with ODE. Allocated once, in the constructor.
  struct Impl;
  std::unique_ptr<Impl> impl_;

  int n_ = 0;
  Eigen::Vector3d gravity_m_s2_;
  bool fail_steps_for_testing_ = false;
  double payload_mass_kg_ = 0.0;

  // Preallocated work space (bounded-size Eigen types live inline: no heap).
  JointVector zero_, effort_, qddot_, q_work_, hdot_qdot_, d_qdot_;
  JointMatrix inverse_mass_, mass_work_, mass_plus_, mass_minus_, identity_;
  Eigen::LLT<JointMatrix> llt_;  // factor of H^-1, stored inline

  // Path terms.
  bool motors_on_ = false;
  JointVector path_acc_, path_qdot_;
  std::array<Eigen::Matrix3d, kMaxJoints + 1> inertia_body_;  // ODE's, body axes, about the CoM
};

}  // namespace craneassist::dynamics
