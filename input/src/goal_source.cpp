#include "craneassist/input/goal_source.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "craneassist/input/hermite.hpp"

namespace craneassist::input {
GoalSource::GoalSource(const GoalSourceSettings& settings) : settings_(settings) {
  for (auto& plan : plans_.slots()) plan.samples.resize(settings.capacity);
}

bool GoalSource::publish(std::span<const TipSample> samples, double start_t_s) {
  if (samples.empty() || samples.size() > settings_.capacity || !std::isfinite(start_t_s)) {
    return false;
  }
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const auto& s = samples[k];
    if (!std::isfinite(s.t_s) || !s.p_m.allFinite() || !s.v_m_s.allFinite()) return false;
    if (k > 0 && !(s.t_s > samples[k - 1].t_s)) return false;
  }
  Plan& plan = plans_.back();
  std::copy(samples.begin(), samples.end(), plan.samples.begin());
  plan.count = samples.size();
  plan.start_t_s = start_t_s;
  plans_.publish();
  return true;
}

bool GoalSource::last_tip(Eigen::Vector3d& tip_m, double& t_s) const noexcept {
  for (int attempt = 0; attempt < 1000; ++attempt) {
    const std::uint64_t before = tip_seq_.load(std::memory_order_acquire);
    if (before == 0) return false;
    if (before & 1U) continue;
    const double x = tip_[0].load(std::memory_order_relaxed);
    const double y = tip_[1].load(std::memory_order_relaxed);
    const double z = tip_[2].load(std::memory_order_relaxed);
    const double t = tip_[3].load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (tip_seq_.load(std::memory_order_relaxed) == before) {
      tip_m = {x, y, z};
      t_s = t;
      return std::isfinite(x) && std::isfinite(y) && std::isfinite(z);
    }
  }
  return false;
}

void GoalSource::sample(double tau_s, Eigen::Vector3d& p, Eigen::Vector3d& v) noexcept {
  const auto& s = plans_.front().samples;
  const std::size_t n = plans_.front().count;
  if (tau_s <= s[0].t_s) {
    p = s[0].p_m;
    v = tau_s < s[0].t_s ? Eigen::Vector3d::Zero() : s[0].v_m_s;
    return;
  }
  if (tau_s >= s[n - 1].t_s) {
    p = s[n - 1].p_m;
    v.setZero();
    return;
  }
  // Machine time only moves forward within a plan: walk the cursor (bounded work per cycle on
  // average; a step back, never expected, restarts the walk).
  if (cursor_ >= n - 1 || s[cursor_].t_s > tau_s) cursor_ = 0;
  while (cursor_ + 1 < n - 1 && s[cursor_ + 1].t_s <= tau_s) ++cursor_;
  const TipSample& a = s[cursor_];
  const TipSample& b = s[cursor_ + 1];
  const double h = b.t_s - a.t_s;
  cubic_hermite(a.p_m, a.v_m_s, b.p_m, b.v_m_s, h, (tau_s - a.t_s) / h, p, v);
}

void GoalSource::begin_cycle(double now_s, const Eigen::Vector3d& tip_m) noexcept {
  now_s_ = now_s;
  tip_m_ = tip_m;
  // The measured tip for the producer.
  tip_seq_.fetch_add(1, std::memory_order_acq_rel);
  for (std::size_t a = 0; a < 3; ++a)
    tip_[a].store(tip_m[static_cast<int>(a)], std::memory_order_relaxed);
  tip_[3].store(now_s, std::memory_order_relaxed);
  tip_seq_.fetch_add(1, std::memory_order_release);
}

SourceState GoalSource::poll(OperatorCommand& out) noexcept {
  // A newer plan?
  if (plans_.update()) {
    cursor_ = 0;
    reached_ = false;
    // A plan taken while the tip is not being commanded starts once the monitor has armed.
    waiting_ = !primed_;
    taken_.fetch_add(1, std::memory_order_acq_rel);
  }
  if (!has_plan()) {
    state_ = "no goal";
    primed_ = false;
    return SourceState::kNoData;
  }
  out.stamp_s = now_s_;
  out.v_m_s.setZero();
  out.deadman = false;
  Eigen::Vector3d v_ref;
  const double tau = now_s_ - plans_.front().start_t_s;
  sample(tau, reference_, v_ref);
  if (!tip_m_.allFinite()) {
    state_ = "no tip measurement";
    primed_ = false;
    return SourceState::kOk;
  }
  const Eigen::Vector3d error = reference_ - tip_m_;
  const bool ended = !waiting_ && tau >= plans_.front().samples[plans_.front().count - 1].t_s;
  if (ended && (reached_ || error.norm() <= settings_.goal_tolerance_m)) {
    reached_ = true;
    state_ = "goal reached";
    primed_ = false;
    return SourceState::kOk;
  }
  // The input monitor arms on a press of the deadman: a cycle released before the first command,
  // then the deadman held still for arming_s; the plan's clock starts after that, so the tip does
  // not begin behind it.
  if (!primed_) {
    primed_ = true;
    primed_at_s_ = now_s_;
    waiting_ = true;
    state_ = "arming";
    return SourceState::kOk;
  }
  if (waiting_) {
    out.deadman = true;
    if (now_s_ - primed_at_s_ < settings_.arming_s) {
      state_ = "arming";
      return SourceState::kOk;
    }
    waiting_ = false;
    plans_.front().start_t_s = now_s_;
    cursor_ = 0;
    sample(0.0, reference_, v_ref);
  }
  Eigen::Vector3d feedback = settings_.position_gain_1_s * (reference_ - tip_m_);
  const double norm = feedback.norm();
  if (norm > settings_.feedback_speed_cap_m_s) {
    feedback *= settings_.feedback_speed_cap_m_s / norm;
  }
  out.v_m_s = v_ref + feedback;
  out.deadman = true;
  state_ = "following";
  return SourceState::kOk;
}

}  // namespace craneassist::input
