#include "craneassist/studies/ptp_simulation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "craneassist/input/hermite.hpp"

namespace craneassist::studies {
namespace {

std::size_t at(int i) {
  return static_cast<std::size_t>(i);
}

// The plan's sample interval containing tau: the index k with t_k <= tau < t_k+1 (clamped).
std::size_t interval(const std::vector<planner::PtpSample>& s, double tau) {
  const auto it = std::upper_bound(s.begin(), s.end(), tau,
                                   [](double t, const planner::PtpSample& x) { return t < x.t_s; });
  if (it == s.begin()) return 0;
  return std::min<std::size_t>(static_cast<std::size_t>(it - s.begin()) - 1, s.size() - 1);
}

// Moving joints of the plan at tau: cubic Hermite on position and rate between the samples,
// acceleration interpolated linearly; at rest at the ends. Modes: the sample's (S4 holds them
// from one sample to the next).
void sample_plan(const planner::PtpPlan& plan, double tau, planner::ArmVector& q,
                 planner::ArmVector& qdot, planner::ArmVector& qddot,
                 std::array<mhsb::MhsbMode, dynamics::kMaxJoints>& modes) {
  const auto& s = plan.samples;
  const std::size_t k = interval(s, tau);
  modes = s[k].mode;
  if (tau <= s.front().t_s || k + 1 >= s.size()) {
    const auto& e = tau <= s.front().t_s ? s.front() : s.back();
    q = e.q;
    qdot = planner::ArmVector::Zero(e.q.size());
    qddot = planner::ArmVector::Zero(e.q.size());
    return;
  }
  const auto &a = s[k], &b = s[k + 1];
  const double h = b.t_s - a.t_s, u = (tau - a.t_s) / h;
  input::cubic_hermite(a.q, a.qdot, b.q, b.qdot, h, u, q, qdot);
  qddot = (1 - u) * a.qddot + u * b.qddot;
}

}  // namespace

PtpSimulation simulate_ptp(planner::PtpPlanner& planner, const Eigen::Vector2d& from,
                           const Eigen::Vector2d& to, const planner::PtpWeights& weights,
                           const std::vector<PtpGoalChange>& changes, double settle_s,
                           std::ostream* csv) {
  const planner::PlanarArm& arm = planner.arm();
  const dynamics::CraneModel& model = arm.model();
  PtpSimulation out;
  PtpSegment first{0.0, from, to, planner.plan(from, to, weights)};
  if (!first.plan.path.found || first.plan.samples.empty()) {
    throw std::runtime_error("no path to the goal within the mode rules");
  }
  out.segments.push_back(std::move(first));

  mhsb::MhsbSimulator sim(model, mhsb::MhsbSettings{},
                          arm.full(out.segments.front().plan.samples.front().q));
  std::vector<PtpGoalChange> pending = changes;
  std::sort(pending.begin(), pending.end(),
            [](const PtpGoalChange& a, const PtpGoalChange& b) { return a.t_s < b.t_s; });
  std::size_t next_change = 0;
  planner::ArmVector q, qdot, qddot;
  std::array<mhsb::MhsbMode, dynamics::kMaxJoints> modes{};
  dynamics::KinematicsData kin;

  const auto reference = [&](double t, mhsb::MhsbReference& ref) {
    // A goal change due: replan from the reference's posture now (the arm follows it closely).
    while (next_change < pending.size() && t >= pending[next_change].t_s) {
      const PtpSegment& current = out.segments.back();
      sample_plan(current.plan, t - current.start_s, q, qdot, qddot, modes);
      PtpSegment next{t, arm.tip(q, kin), pending[next_change].xz, {}};
      next.plan = planner.plan(next.from, next.to, weights, q);
      if (!next.plan.path.found || next.plan.samples.empty()) {
        throw std::runtime_error("no path to the goal changed at " + std::to_string(t) + " s");
      }
      out.segments.push_back(std::move(next));
      ++next_change;
    }
    const PtpSegment& seg = out.segments.back();
    sample_plan(seg.plan, t - seg.start_s, q, qdot, qddot, modes);
    const int n = model.dof();
    ref.q = arm.full(q);
    ref.qdot = dynamics::JointVector::Zero(n);
    ref.qddot = dynamics::JointVector::Zero(n);
    ref.modes = mhsb::ModePattern{};
    ref.modes.dof = n;
    for (int k = 0; k < arm.moving(); ++k) {
      ref.qdot[arm.joint(k)] = qdot[k];
      ref.qddot[arm.joint(k)] = qddot[k];
      ref.modes.mode[at(arm.joint(k))] = modes[at(k)];
    }
  };
  // Run until the last plan (the goal changes included) has ended, plus settle_s.
  const int n = model.dof();
  const double period = sim.settings().controller.period_s;
  auto& m = out.measured;
  m.max_abs_error.setZero(n);
  m.max_p_supply_pa.setZero(n);
  if (csv) mhsb::write_mhsb_csv_header(*csv, n, sim.servo_pumps());
  mhsb::MhsbReference ref;
  for (long k = 0;; ++k) {
    const double t = static_cast<double>(k) * period;
    const PtpSegment& last = out.segments.back();
    const bool changes_left = next_change < pending.size();
    if (!changes_left && t > last.start_s + last.plan.time_s + settle_s) break;
    reference(t, ref);
    const auto status = sim.step(ref);
    if (status == mhsb::MhsbStepStatus::kInvalidReference) ++m.invalid_references;
    if (status == mhsb::MhsbStepStatus::kDynamicsFailed) ++m.dynamics_failures;
    const auto& st = sim.state();
    m.max_abs_error = m.max_abs_error.cwiseMax(st.q_error.cwiseAbs());
    m.max_p_supply_pa = m.max_p_supply_pa.cwiseMax(st.p_supply_pa);
    if (csv) mhsb::write_mhsb_csv_row(*csv, st, ref, sim.servo_pumps());
    m.duration_s = t + period;
  }
  m.max_abs_error_any = m.max_abs_error.maxCoeff();
  m.main_energy_j = sim.state().main_energy_j;
  m.servo_pump_energy_j = sim.state().servo_pump_energy_j;
  m.energy_j = m.main_energy_j + m.servo_pump_energy_j;
  out.duration_s = m.duration_s;
  out.final_error_rad = sim.state().q_error.cwiseAbs().maxCoeff();

  // The planned energy of what ran: each segment until the next took over.
  for (std::size_t i = 0; i < out.segments.size(); ++i) {
    const auto& seg = out.segments[i];
    const double until = i + 1 < out.segments.size() ? out.segments[i + 1].start_s - seg.start_s
                                                     : out.duration_s - seg.start_s;
    if (until >= seg.plan.time_s) {
      out.planned_energy_j += seg.plan.energy_j;
      // Held at the plan's end until the next goal: its holding power (leakage, boost).
      const auto& end = seg.plan.samples.back();
      out.planned_energy_j +=
          (until - seg.plan.time_s) *
          planner.power_w(end.q, planner::ArmVector::Zero(end.q.size()), end.mode);
      continue;
    }
    // Part of a plan: its power integrated over the samples up to `until`.
    const auto& s = seg.plan.samples;
    for (std::size_t k = 0; k + 1 < s.size() && s[k].t_s < until; ++k) {
      const double dt = std::min(s[k + 1].t_s, until) - s[k].t_s;
      out.planned_energy_j += dt * planner.power_w(s[k].q, s[k].qdot, s[k].mode);
    }
  }
  return out;
}

}  // namespace craneassist::studies
