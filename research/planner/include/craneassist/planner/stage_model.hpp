// The stage model of the offline redundancy planner (paper 000 sections 4-5, docs/algorithms.md
// section 7): a prescribed tip path sampled every dt, the extension cylinder's position c and
// velocity v as the state, its acceleration a as the control, and a running cost per stage.
//
// The state fixes the whole crane. With the tip position p_k and the extension known, slew, lift
// and tilt follow from the loader inverse kinematics (paper 000 eq. 33); with the tip velocity
// and the extension rate, their rates (eq. 34); with the tip acceleration and the extension
// acceleration, their accelerations (eq. 35). So at stage k and cylinder position c:
//   qdot(t)     = base + slope t                         (t = q4dot = v / arm4, affine)
//   qddot(t, u) = w0 + w1 t + w2 t^2 + slope u           (u = q4ddot = a / arm4; the quadratic
//                                                         part is -J123^-1 Jdot qdot)
//   tau(t, u)   = tau0 + tau1 t + tau2 t^2 + m u         (inverse dynamics: H qddot + C qdot + g)
// Each coefficient is exact (the dependence really is polynomial of that degree), so the planner
// computes them once per (stage, c) from the ODE model (RigidBodyTerms::path_terms, four calls)
// and evaluates every (v, a) of the grid with a few multiply-adds.
//
// Costs (energy over the stage, J, or m^2/s for kExtension):
//   kLoadSensing:     (max_i p_i + dp_LS) Q dt           (paper 000 eq. 36, 40-41)
//   kConstantPressure: p_s Q dt                           (eq. 43, constant pump efficiency)
//   kActuatorEnergy:  sum_i max(F_i v_i, 0) dt           (positive actuator work)
//   kExtension:       v^2 dt                             (extension cylinder use)
// with Q the pump flow of the cylinder velocities and p_i the load pressure of a moving cylinder
// doing positive work (zero otherwise, eq. 41's Heaviside factors). Limits of every cylinder
// (position through the joint range, velocity, acceleration) and the relief pressure are
// penalties: a large constant plus a term growing with the relative excess (paper 000 section
// 4.4).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "craneassist/dynamics/enum_names.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"

namespace craneassist::planner {

using dynamics::JointVector;

enum class PlanCost { kLoadSensing, kConstantPressure, kActuatorEnergy, kExtension };
inline constexpr std::array kPlanCosts{PlanCost::kLoadSensing, PlanCost::kConstantPressure,
                                       PlanCost::kActuatorEnergy, PlanCost::kExtension};
const char* to_string(PlanCost cost);  // "ls", "cp", "actuator-energy", "extension"
inline std::optional<PlanCost> parse_plan_cost(std::string_view text) {
  return parse_name(kPlanCosts, text);
}

// The prescribed tip motion sampled at t_k = k dt, k = 0..N (crane frame, SI).
struct TipSamples {
  double dt_s = 0.05;
  std::vector<Eigen::Vector3d> p_m, v_m_s, a_m_s2;
  int stages() const { return static_cast<int>(p_m.size()) - 1; }  // N
};

struct StageModelOptions {
  PlanCost cost = PlanCost::kLoadSensing;
  double cp_supply_pressure_pa = 20e6;  // kConstantPressure (paper 000 section 6)
  double penalty_factor = 1e3;          // penalty constant over the cost's scale per stage
  // A cylinder slower than this is at rest: its valve stays closed (the follower's activation
  // rule), so its load pressure does not count.
  double at_rest_speed_m_s = 1e-4;
};

// Per (stage, cylinder position): everything that does not depend on v or a.
struct PositionTerms {
  bool reachable = false;           // the loader inverse kinematics has a solution
  double violation = 0.0;           // relative excess over joint ranges (0 when within)
  JointVector q;                    // joint positions
  JointVector arm, arm_slope;       // dc/dq and d2c/dq2 per cylinder
  JointVector base, slope;          // qdot = base + slope t
  JointVector w0, w1, w2;           // qddot = w0 + w1 t + w2 t^2 + slope u
  JointVector tau0, tau1, tau2, m;  // tau = tau0 + tau1 t + tau2 t^2 + m u
};

// Per (stage, position, velocity): what remains affine in the control u.
struct VelocityTerms {
  double t = 0.0;              // q4dot
  JointVector qdot;            // joint rates
  JointVector v;               // cylinder velocities
  JointVector acc0, acc1;      // cylinder accelerations acc0 + acc1 u
  JointVector force0, force1;  // cylinder forces force0 + force1 u (N)
  JointVector inv_area;        // sign(v_i) / flow area: pressure p_i = F_i * inv_area_i
  std::uint32_t moving = 0;    // bit i: |v_i| above the at-rest threshold
  double flow_m3_s = 0.0;      // pump flow Q
  double base_cost = 0.0;      // the cost part that does not depend on u (cp, extension)
  double penalty = 0.0;        // position and velocity penalties
};

struct StageCost {
  double cost = 0.0;     // principal cost of the stage
  double penalty = 0.0;  // limit penalties
  double total() const { return cost + penalty; }
};

class StageModel {
 public:
  // Throws std::invalid_argument unless the model has the loader structure with a constant-arm
  // extension cylinder, and the samples hold at least two points.
  StageModel(const dynamics::CraneModel& model, TipSamples samples,
             const StageModelOptions& options);

  const dynamics::CraneModel& model() const { return model_; }
  const TipSamples& samples() const { return samples_; }
  const StageModelOptions& options() const { return options_; }
  int stages() const { return samples_.stages(); }
  double dt() const { return samples_.dt_s; }

  // Extension cylinder: position range, velocity and acceleration limits, arm (m per m of q4).
  double c_min() const { return c_min_; }
  double c_max() const { return c_max_; }
  double v_max() const { return v_max_; }
  double a_max() const { return a_max_; }
  double extension_arm() const { return arm4_; }
  double q4_of(double c) const { return (c - c0_) / arm4_; }
  double c_of(double q4) const { return c0_ + arm4_ * q4; }

  // The cost scale of one stage (penalties are options().penalty_factor times this).
  double stage_scale() const { return scale_; }

  // Terms at stage k (0..N) and extension cylinder position c. `terms` is one probe per thread.
  void position_terms(int k, double c, dynamics::RigidBodyTerms& terms, PositionTerms& out) const;
  void velocity_terms(const PositionTerms& pos, double v, VelocityTerms& out) const;
  StageCost cost(const VelocityTerms& vel, double a) const;
  // cost(vel, a).total() for a = a0 + l da, l = 0..count-1, into totals (the planner's inner loop).
  void total_costs(const VelocityTerms& vel, double a0, double da, int count, double* totals) const;
  // Joint accelerations at control a.
  void joint_accelerations(const PositionTerms& pos, const VelocityTerms& vel, double a,
                           JointVector& qddot) const;

  // Convenience: the whole evaluation at (k, c, v, a).
  StageCost evaluate(int k, double c, double v, double a, dynamics::RigidBodyTerms& terms) const;

 private:
  const dynamics::CraneModel& model_;
  TipSamples samples_;
  StageModelOptions options_;
  double c0_ = 0.0, arm4_ = 1.0, c_min_ = 0.0, c_max_ = 0.0, v_max_ = 0.0, a_max_ = 0.0;
  double scale_ = 1.0, penalty_ = 1.0;
  std::array<double, 4> inv_a_max_{};  // 1 / cylinder acceleration limits
};

}  // namespace craneassist::planner
