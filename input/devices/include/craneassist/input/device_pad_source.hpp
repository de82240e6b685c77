// What the physical joysticks (EvdevSource, SdlSource) share: a reader thread that calls the
// device's service() in a loop, service() publishing the pad's state to a LatestPad, and the
// loop's side: poll() takes the latest state without waiting and maps it (joystick_mapping.hpp).
#pragma once

#include <atomic>
#include <thread>

#include "craneassist/input/command_source.hpp"
#include "craneassist/input/joystick_mapping.hpp"
#include "craneassist/input/latest_pad.hpp"

namespace craneassist::input {

class DevicePadSource : public CommandSource {
 public:
  DevicePadSource(const DevicePadSource&) = delete;
  DevicePadSource& operator=(const DevicePadSource&) = delete;

  void begin_cycle(double now_s, const Eigen::Vector3d& tip_m) noexcept override;
  // kDisconnected without a device, kNoData before its first complete state, else the state
  // mapped at the tip of the last begin_cycle().
  SourceState poll(OperatorCommand& out) noexcept override;

  // One round of the reader's work; the reader thread calls it in a loop.
  virtual void service() = 0;

 protected:
  explicit DevicePadSource(const JoystickMapping& mapping) : mapper_(mapping) {}
  ~DevicePadSource() override = default;

  // Starts the reader thread, which calls service() until stop_reader(): last in the derived
  // class's constructor (service() uses its members).
  void start_reader();
  // Stops and joins the reader thread, if started: first in the derived class's destructor.
  void stop_reader() noexcept;

  LatestPad latest_;  // service() publishes here

 private:
  JoystickMapper mapper_;
  PadSnapshot taken_;
  Eigen::Vector3d tip_ = Eigen::Vector3d::UnitX();
  std::atomic<bool> running_{true};
  std::thread thread_;
};

}  // namespace craneassist::input
