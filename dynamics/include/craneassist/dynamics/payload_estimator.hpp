// The crane scale: the payload in the grapple, estimated online from the cylinder pressures, the
// joint states and the crane's model (docs/loads.md).
//
// Model. Each cylinder's force from its two chamber pressures, F = p_A A_A - p_B A_B, gives the
// joint effort tau = F dc/dq. The crane's own inverse dynamics with an empty grapple,
// tau_0 = H qddot + C(q, qdot) qdot + g (RigidBodyTerms::path_terms on a probe whose payload is
// 0), and the known cylinder friction leave the part a point payload m at the tip explains:
//     tau - tau_0 - tau_friction = m y,   y = J^T (a_tip - gravity),
// with J the tip's linear Jacobian and a_tip = J qddot + Jdot qdot. qdot, qddot and the efforts
// are low-pass filtered alike (a critically damped second-order filter), so their phases match.
//
// Estimation. Weighted recursive least squares on the one unknown m, each joint a row weighted by
// its expected error (sensor noise through the piston areas; while moving, the friction's and the
// dynamics' uncertainty), with exponential forgetting. Only trustworthy rows are used: both
// chambers measured and finite, the joint off its end stops, no chamber near a relief setting,
// the row informative (|y| large enough). A load change (the cycle's own estimate far from the
// running one for a while) restarts the estimate from the new data.
//
// Convergence: settled for settle_time_s after a (re)start with the estimate's standard error
// under converged_sigma_kg. Until then a caller that must not underestimate uses
// max(rated load, estimate) (PayloadEstimate::conservative_kg does).
//
// Model and data in one small class; the constructor allocates (its ODE probe), update() does not
// and never throws (cycle-safe).
#pragma once

#include <algorithm>
#include <array>
#include <memory>

#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"

namespace craneassist::dynamics {

struct PayloadEstimatorSettings {
  double period_s = 0.01;
  double filter_hz = 3.0;           // the second-order low-pass on rates and efforts
  double memory_s = 3.0;            // forgetting time constant of the least squares
  double settle_time_s = 0.5;       // data needed after a (re)start before convergence
  double converged_sigma_kg = 5.0;  // standard error below which the estimate has converged
  // Expected errors of a row: the chamber pressure sensors' noise (after the filter, per
  // chamber), and while moving a share of the friction force and of the dynamic effort.
  double pressure_noise_pa = 0.05e6;
  double friction_uncertainty = 0.3;
  double dynamics_uncertainty = 0.1;
  // A chamber at or above this share of the lower relief setting (pump or load-holding valve)
  // makes its row untrustworthy (the relief valve, not the load, sets the pressure).
  double relief_share = 0.95;
  // A joint within this share of its range of an end is on or near its stop.
  double end_share = 0.01;
  // A new load: the cycle's own estimate this many standard errors from the running one, for
  // change_time_s (longer than the pressure transient of a stop, which a machine's differentiated
  // encoder rates do not show in step).
  double change_sigmas = 6.0;
  double change_time_s = 0.25;
};

struct PayloadEstimate {
  double mass_kg = 0.0;   // the estimate (>= 0)
  double sigma_kg = 0.0;  // its standard error (infinite before any data)
  bool converged = false;
  int rows = 0;       // rows used in the last update
  long restarts = 0;  // load changes detected
  // What a caller that must not underestimate uses: the estimate once converged, else the larger
  // of it and the rated load.
  double conservative_kg(double rated_kg) const {
    return converged ? mass_kg : std::max(mass_kg, rated_kg);
  }
};

class PayloadEstimator {
 public:
  // model: the crane (its payload body's mass is ignored: the probe uses 0). Throws as
  // RigidBodyTerms' constructor does.
  PayloadEstimator(const CraneModel& model, const PayloadEstimatorSettings& settings);
  ~PayloadEstimator();
  PayloadEstimator(const PayloadEstimator&) = delete;
  PayloadEstimator& operator=(const PayloadEstimator&) = delete;

  // Forgets everything (the next valid update starts the filters at that state).
  void reset() noexcept;

  // One control period. valid: the measurement can be used at all; without chamber pressures
  // (pressures false) the estimate holds, and a cylinder with a chamber not measured (NaN)
  // gives no row. No allocation, no exception.
  const PayloadEstimate& update(bool valid, const JointVector& q, const JointVector& qdot,
                                bool pressures, const JointVector& pressure_a_pa,
                                const JointVector& pressure_b_pa) noexcept;
  const PayloadEstimate& estimate() const noexcept { return out_; }

 private:
  void restart() noexcept;

  CraneModel model_;
  PayloadEstimatorSettings settings_;
  std::unique_ptr<RigidBodyTerms> terms_;  // the crane with an empty grapple
  KinematicsData kin_;
  TaskJacobian jac_, jac_ahead_;
  PathTerms path_terms_;
  PayloadEstimate out_;
  bool started_ = false;
  // Filter states: rates and their derivative; efforts and their derivative.
  JointVector rate_f_, acc_f_, effort_f_, effort_d_, arms_, effort_, row_y_;
  JointVector gravity_effort_, inertial_, payload_inertial_;
  std::array<bool, kMaxJoints> measured_{};  // both chambers of the cylinder measured this cycle
  double theta_ = 0.0;                       // the running estimate, kg
  double information_ = 0.0;  // sum of weights * y^2 (inverse variance), forgetting applied
  double since_restart_s_ = 0.0;
  double change_time_s_ = 0.0;
};

}  // namespace craneassist::dynamics
