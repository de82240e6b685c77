#include "craneassist/input/device_pad_source.hpp"

namespace craneassist::input {

void DevicePadSource::start_reader() {
  thread_ = std::thread([this] {
    while (running_.load()) service();
  });
}

void DevicePadSource::stop_reader() noexcept {
  running_.store(false);
  if (thread_.joinable()) thread_.join();
}

void DevicePadSource::begin_cycle(double /*now_s*/, const Eigen::Vector3d& tip_m) noexcept {
  tip_ = tip_m;
}

SourceState DevicePadSource::poll(OperatorCommand& out) noexcept {
  latest_.try_take(taken_);
  if (!taken_.connected) return SourceState::kDisconnected;
  if (!taken_.has_state) return SourceState::kNoData;
  out.v_m_s = mapper_.map(taken_.pad, tip_);
  out.deadman = mapper_.deadman(taken_.pad);
  out.drive = mapper_.drive(taken_.pad);
  out.stamp_s = taken_.stamp_s;
  return SourceState::kOk;
}

}  // namespace craneassist::input
