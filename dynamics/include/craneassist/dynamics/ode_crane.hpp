// The crane as Open Dynamics Engine (ODE) rigid bodies and joints.
//
// Shared by the simulator, which steps it in its own world with its own ERP/CFM, and by
// RigidBodyTerms, which probes it for H(q), C(q,qdot)qdot and g(q) (docs/algorithms.md section 3).
//
// Conventions:
// - The ODE world frame is the DH base frame (frame 0). The caller sets the world's gravity
//   (normally model.gravity_m_s2); this class does not touch world parameters.
// - One ODE body per DH frame i = 1..n, carrying every model body attached to that frame. ODE
//   wants the body position at the centre of mass, so body i sits at o_i + R_i * com_i with
//   orientation R_i (body axes = frame-i axes).
// - Joint i joins body i (first) to body i-1 (second; the static environment for i = 1) along
//   z_{i-1}; with that attachment order ODE's positive hinge angle / slider position is +q_i.
// - ODE measures joint coordinates relative to the pose in which a joint was created. The joints
//   are created with every joint in the middle of its range (or at q_initial when the model gives
//   no range), then the bodies are moved to q_initial. That reference makes ODE's hinge angle,
//   which lives in (-pi, pi] relative, cover [q_mid - pi, q_mid + pi], so read_state() returns q
//   inside any joint range narrower than a full turn, and the end stops fit ODE's [-pi, pi] rule.
//
// ODE must be initialised before the world is created: call ensure_ode_initialized() first.
// The world must outlive this object. Not copyable or movable (it owns ODE handles).
// A world that may be stepped while another world is stepped in another thread needs its own
// threading implementation (dThreadingAllocateSelfThreadedImplementation, then
// dWorldSetStepThreadingImplementation): by default all worlds share one process-wide instance,
// and parallel steps abort inside ODE. RigidBodyTerms does this for its probe world.
//
// The one public dynamics header that includes <ode/ode.h>. ODE is a private dependency of the
// dynamics target (RigidBodyTerms keeps its ODE state behind a pimpl), so a target that includes
// this header links PkgConfig::ODE itself: sim_backend (privately) and the tests that step or
// count ODE directly. It stays public rather than in a private include directory because the
// simulator, another module, builds its crane from it.
#pragma once

#include <ode/ode.h>

#include <Eigen/Core>
#include <array>

#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

// Process-wide, thread-safe ODE initialisation (dInitODE2 once, per-thread ODE data for the
// calling thread). Cheap after the first call; call it on every thread that uses ODE.
void ensure_ode_initialized();

class OdeCrane {
 public:
  // Builds bodies and joints in `world` and leaves the crane at (q_initial, 0). Throws
  // std::invalid_argument for a model with no joints, more than kMaxJoints joints, a body on a
  // frame outside 1..n, or a q_initial of the wrong size.
  OdeCrane(const CraneModel& model, dWorldID world, const JointVector& q_initial);
  ~OdeCrane();
  OdeCrane(const OdeCrane&) = delete;
  OdeCrane& operator=(const OdeCrane&) = delete;

  // Puts every body at the pose and (linear, angular) velocity that (q, qdot) imply, exactly.
  // Does not touch force/torque accumulators. No allocation.
  void set_state(const JointVector& q, const JointVector& qdot);

  // Joint coordinates and rates from the current body states. Hinge rates come from ODE; slider
  // rates are computed here because dJointGetSliderPositionRate differences the two bodies'
  // centre-of-mass velocities, which wrongly includes omega x (com_child - com_parent) when the
  // slider rotates and the centres of mass are not on the slider axis. No allocation.
  void read_state(JointVector& q, JointVector& qdot) const;

  // Joint rates from the bodies' current velocities, but measured with the axes and centres of
  // mass of the pose last given to set_state(), not the pose the bodies were moved to by a step.
  // After set_state(q, 0) and one dWorldStep, ODE's velocity-level solution satisfies the joint
  // constraints linearised at the set_state pose exactly, so this reading is exactly dt * qddot
  // (read_state() would be off by O(dt^2) relative through the moved slider geometry).
  void read_rates_at_set_pose(JointVector& qdot) const;

  // Adds generalized joint efforts (N m on hinges, N on sliders) for the next step. ODE clears
  // the accumulators after each step. No allocation.
  void add_joint_efforts(const JointVector& tau);

  // Sets the mass of the model's body named "payload" (kg, >= 0; no such body: nothing happens)
  // and re-merges the bodies of its frame: the body's mass and inertia, its centre of mass. The
  // body keeps its position, so this is for a crane that set_state() places before each use (the
  // dynamics probe), not for one being stepped (the simulator carries its load on a body of its
  // own). No allocation.
  void set_payload_mass(double mass_kg) noexcept;

  // End stops at model.joints[i].q_min / q_max (joints with q_max <= q_min get none). ODE's hinge
  // stops must lie inside [-pi, pi] relative to the creation pose and its angle wraps at +-pi, so
  // a revolute range of (nearly) a full turn is shrunk to +-(pi - kHingeStopMargin) around the
  // reference; otherwise a stop reached from one side would be seen on the other after the wrap.
  // The stops use the world's ERP and CFM unless the caller sets dParamStopERP / dParamStopCFM on
  // joint(i).
  void enable_end_stops(bool on);

  // i = 1..n (DH frame / joint numbering).
  dBodyID body(int i) const { return bodies_[static_cast<size_t>(i)]; }
  dJointID joint(int i) const { return joints_[static_cast<size_t>(i)]; }
  int dof() const { return n_; }

  // Merged centre of mass of body i in frame-i axes, relative to the frame-i origin.
  const Eigen::Vector3d& com_local(int i) const { return com_local_[static_cast<size_t>(i)]; }
  // Merged mass of body i as given to ODE (including the placeholder mass of an empty frame).
  double mass(int i) const { return mass_[static_cast<size_t>(i)]; }
  // The joint coordinates at which ODE's joint coordinates are zero.
  const JointVector& joint_reference() const { return q_ref_; }
  // Frame poses, angular velocities and origin velocities of the last set_state().
  const KinematicsData& kinematics() const { return kin_; }
  const CraneModel& model() const { return model_; }

  static constexpr double kEmptyFrameMassKg = 1e-6;
  static constexpr double kHingeStopMargin = 0.01;  // rad

 private:
  CraneModel model_;
  int n_ = 0;
  KinematicsData kin_;
  JointVector q_ref_;
  // Index 0 is the static environment (nullptr); 1..n are the crane's bodies / joints.
  std::array<dBodyID, kMaxJoints + 1> bodies_{};
  std::array<dJointID, kMaxJoints + 1> joints_{};
  std::array<Eigen::Vector3d, kMaxJoints + 1> com_local_;
  std::array<double, kMaxJoints + 1> mass_{};
};

}  // namespace craneassist::dynamics
