#include "craneassist/dynamics/payload_estimator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/static_gravity.hpp"

namespace craneassist::dynamics {
namespace {

constexpr int kFilterSubsteps = 4;
// Cylinder speed over which the estimator's friction model turns from one direction to the
// other, m/s (the machine's own friction law is not known that closely).
constexpr double kFrictionSignSpeed = 5e-3;
// A cylinder faster than this counts as moving (the friction and dynamics uncertainty apply).
constexpr double kMovingSpeed = 2e-3;
// The least squares' memory after a (re)start: this share of the time since.
constexpr double kMemoryGrowth = 0.2;

CraneModel with_empty_grapple(const CraneModel& model) {
  CraneModel m = model;
  set_payload_mass_kg(m, 0.0);
  return m;
}

}  // namespace

PayloadEstimator::PayloadEstimator(const CraneModel& model,
                                   const PayloadEstimatorSettings& settings)
    : model_(with_empty_grapple(model)),
      settings_(settings),
      terms_(std::make_unique<RigidBodyTerms>(model_)) {
  const int n = model_.dof();
  rate_f_ = JointVector::Zero(n);
  acc_f_ = JointVector::Zero(n);
  effort_f_ = JointVector::Zero(n);
  effort_d_ = JointVector::Zero(n);
  arms_ = JointVector::Zero(n);
  effort_ = JointVector::Zero(n);
  row_y_ = JointVector::Zero(n);
  gravity_effort_ = JointVector::Zero(n);
  inertial_ = JointVector::Zero(n);
  payload_inertial_ = JointVector::Zero(n);
  path_terms_.m = JointVector::Zero(n);
  path_terms_.b = JointVector::Zero(n);
  reset();
}

PayloadEstimator::~PayloadEstimator() = default;

void PayloadEstimator::reset() noexcept {
  started_ = false;
  out_ = PayloadEstimate{};
  out_.sigma_kg = std::numeric_limits<double>::infinity();
  theta_ = 0.0;
  information_ = 0.0;
  since_restart_s_ = 0.0;
  change_time_s_ = 0.0;
}

void PayloadEstimator::restart() noexcept {
  out_.converged = false;
  information_ = 0.0;
  since_restart_s_ = 0.0;
  change_time_s_ = 0.0;
  ++out_.restarts;
}

const PayloadEstimate& PayloadEstimator::update(bool valid, const JointVector& q,
                                                const JointVector& qdot, bool pressures,
                                                const JointVector& pressure_a_pa,
                                                const JointVector& pressure_b_pa) noexcept {
  const int n = model_.dof();
  out_.rows = 0;
  if (!valid || !pressures || q.size() != n || qdot.size() != n || pressure_a_pa.size() != n ||
      pressure_b_pa.size() != n || !q.allFinite() || !qdot.allFinite()) {
    return out_;  // holds
  }
  cylinder_arms(model_, q, arms_);
  // A cylinder whose chambers are not both measured (NaN) gives no row; its filtered effort is
  // kept at zero.
  for (int i = 0; i < n; ++i) {
    const auto& c = model_.cylinders[static_cast<std::size_t>(i)];
    effort_[i] = (pressure_a_pa[i] * c.area_a_m2 - pressure_b_pa[i] * c.area_b_m2) * arms_[i];
    measured_[static_cast<std::size_t>(i)] = std::isfinite(effort_[i]);
    if (!measured_[static_cast<std::size_t>(i)]) effort_[i] = 0.0;
  }

  // The second-order low-pass (critically damped) on the rates and on the efforts alike.
  const double w = 2.0 * std::numbers::pi * settings_.filter_hz;
  if (!started_) {
    rate_f_ = qdot;
    acc_f_.setZero();
    effort_f_ = effort_;
    effort_d_.setZero();
  } else {
    const double h = settings_.period_s / kFilterSubsteps;
    for (int k = 0; k < kFilterSubsteps; ++k) {
      acc_f_ += h * (w * w * (qdot - rate_f_) - 2.0 * w * acc_f_);
      rate_f_ += h * acc_f_;
      effort_d_ += h * (w * w * (effort_ - effort_f_) - 2.0 * w * effort_d_);
      effort_f_ += h * effort_d_;
    }
  }

  // The crane's own inverse dynamics with an empty grapple, and its gravity part.
  if (!terms_->path_terms(q, rate_f_, acc_f_, 1.0, path_terms_)) return out_;
  static_gravity_effort(model_, kin_, q, gravity_effort_);
  const JointVector& tau0 = path_terms_.b;

  // y = J^T (a_tip - gravity), crane frame.
  tip_jacobian(model_, kin_, q, jac_);
  tip_jacobian_dot(model_, kin_, q, rate_f_, jac_ahead_);
  const Eigen::Vector3d a_tip = jac_ * acc_f_ + jac_ahead_ * rate_f_;
  const Eigen::Vector3d gravity = model_.task_from_base * model_.gravity_m_s2;
  inertial_ = tau0 - gravity_effort_;            // H qddot + C qdot of the empty crane
  payload_inertial_ = jac_.transpose() * a_tip;  // per kg of payload
  row_y_ = jac_.transpose() * (a_tip - gravity);

  const double pump_relief = model_.pump.max_pressure_pa;
  const double hold_relief = load_holding_relief_pa(model_);
  // Correlated samples: the filter passes about 2 f_c independent values a second.
  const double kappa = std::min(1.0, 2.0 * settings_.filter_hz * settings_.period_s);
  double info = 0.0, moment = 0.0;  // this cycle's sum w y^2 and sum w y r
  for (int i = 0; i < n; ++i) {
    const auto& c = model_.cylinders[static_cast<std::size_t>(i)];
    const auto& j = model_.joints[static_cast<std::size_t>(i)];
    if (!measured_[static_cast<std::size_t>(i)]) continue;
    const double range = j.q_max - j.q_min;
    if (range > 0.0 && (q[i] <= j.q_min + settings_.end_share * range ||
                        q[i] >= j.q_max - settings_.end_share * range)) {
      continue;  // on or near the end stop: the stop carries some of the load
    }
    const double vc = rate_f_[i] * arms_[i];
    const double force = effort_f_[i] / arms_[i];
    const bool row_moving = std::abs(vc) > kMovingSpeed;
    // Pushed by the pump, the pump's relief caps the pressure; held or over-running, the
    // load-holding valve's.
    const double relief = row_moving && vc * force > 0.0 ? pump_relief : hold_relief;
    if (std::max(pressure_a_pa[i], pressure_b_pa[i]) >= settings_.relief_share * relief) continue;
    const auto& fr = c.friction;
    const double fc = vc >= 0.0 ? fr.coulomb_extend_n : fr.coulomb_retract_n;
    const double friction = friction_force_n(fr, vc, kFrictionSignSpeed) * arms_[i];
    const double y = row_y_[i];
    const double r = effort_f_[i] - tau0[i] - friction;
    const double noise =
        settings_.pressure_noise_pa * std::hypot(c.area_a_m2, c.area_b_m2) * std::abs(arms_[i]);
    // The dynamics' share of the error whenever the crane accelerates (a stop's last
    // centimetres too), the friction's while the cylinder moves.
    const double d_err = settings_.dynamics_uncertainty *
                         (std::abs(inertial_[i]) + std::abs(theta_ * payload_inertial_[i]));
    double var = noise * noise + d_err * d_err;
    if (row_moving) {
      const double f_err = settings_.friction_uncertainty * (fc + fr.viscous_n_s_m * std::abs(vc)) *
                           std::abs(arms_[i]);
      var += f_err * f_err;
    }
    if (!(var > 0.0) || !std::isfinite(r) || !std::isfinite(y)) continue;
    info += y * y / var;
    moment += y * r / var;
    ++out_.rows;
  }
  if (out_.rows == 0 || !(info > 0.0)) return out_;

  const double theta_cycle = moment / info;
  if (!started_) {
    started_ = true;
    theta_ = theta_cycle;
    information_ = kappa * info;
  } else {
    // A load change: this cycle's own estimate far from the running one, for a while.
    const double spread = std::sqrt(1.0 / info + 1.0 / std::max(information_, 1e-300));
    if (std::abs(theta_cycle - theta_) > settings_.change_sigmas * spread) {
      change_time_s_ += settings_.period_s;
    } else {
      change_time_s_ = 0.0;
    }
    if (change_time_s_ >= settings_.change_time_s) {
      restart();
      theta_ = theta_cycle;
    }
    // A memory that grows with the time since the (re)start: the filters' transient after a
    // load change is forgotten within a fraction of a second, a steady load averaged over
    // memory_s.
    const double memory =
        std::clamp(kMemoryGrowth * since_restart_s_, settings_.period_s, settings_.memory_s);
    information_ = information_ * std::exp(-settings_.period_s / memory) + kappa * info;
    theta_ += kappa * (moment - info * theta_) / information_;
  }
  since_restart_s_ += settings_.period_s;
  out_.mass_kg = std::max(theta_, 0.0);
  out_.sigma_kg = 1.0 / std::sqrt(information_);
  // Converged stays converged until the next load change: the dynamics must not swing between
  // the estimate and the rated load while the crane moves (the moving rows' wider errors raise
  // the standard error again).
  out_.converged = out_.converged || (since_restart_s_ >= settings_.settle_time_s &&
                                      out_.sigma_kg <= settings_.converged_sigma_kg);
  return out_;
}

}  // namespace craneassist::dynamics
