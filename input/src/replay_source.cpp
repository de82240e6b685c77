#include "craneassist/input/replay_source.hpp"

namespace craneassist::input {

void ReplaySource::begin_cycle(double now_s, const Eigen::Vector3d& /*tip_m*/) noexcept {
  if (!started_) {
    started_ = true;
    start_s_ = now_s;
  }
  now_s_ = now_s;
}

SourceState ReplaySource::poll(OperatorCommand& out) noexcept {
  if (!started_) return SourceState::kNoData;
  out.stamp_s = now_s_;
  out.v_m_s = cursor_.command_at(now_s_ - start_s_);
  out.deadman = cycles_ > 0;
  if (!out.v_m_s.allFinite()) {  // a stop row: the operator lets go of the deadman
    out.v_m_s.setZero();
    out.deadman = false;
  }
  ++cycles_;
  return SourceState::kOk;
}

}  // namespace craneassist::input
