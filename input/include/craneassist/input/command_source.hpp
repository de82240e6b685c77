// A live source of operator commands (physical joystick, keyboard, DDS command topic, replay):
// the contract between the input devices and the real-time loop.
//
// The loop calls poll() once per cycle. poll() never blocks, never allocates and never throws:
// a source that needs a thread or a device read does that elsewhere, or with non-blocking reads,
// and hands the latest sample over without locks. Safety decisions (stale data, NaN, released
// deadman) are made by the loop's input monitor from what poll() returns, not by the source.
#pragma once

#include <Eigen/Core>

namespace craneassist::input {

struct OperatorCommand {
  // When the source got this sample, seconds on the loop's clock (std::chrono::steady_clock
  // since its epoch, or machine time for scripted sources). A sample that is not renewed goes
  // stale; a source that repeats an old sample must keep its old stamp.
  double stamp_s = 0.0;
  Eigen::Vector3d v_m_s =
      Eigen::Vector3d::Zero();  // tip velocity, crane frame (x fwd, y up, z lat)
  bool deadman = false;         // enable button held
  // The drive stick of a crane on a wheeled base (sim --base, docs/mobile.md#live): forward
  // speed and curvature as fractions of their flow-bounded and steering limits, each in
  // [-1, 1] (curvature positive: turning left). Zero for sources without one.
  Eigen::Vector2d drive = Eigen::Vector2d::Zero();
};

enum class SourceState {
  kOk,            // connected; the sample may still be stale, the monitor judges that
  kNoData,        // connected, nothing received yet
  kDisconnected,  // the device went away (hot-unplug, DDS writer lost, terminal closed)
};
const char* to_string(SourceState state);

// The clock of real-time sources' stamps: std::chrono::steady_clock seconds since its epoch.
double steady_now_s() noexcept;

class CommandSource {
 public:
  virtual ~CommandSource() = default;
  // The latest sample (out is left unchanged when there is none). Non-blocking, allocation-free.
  virtual SourceState poll(OperatorCommand& out) noexcept = 0;
  // Called by the loop before each poll(): the loop's clock (seconds, the clock stamps are on)
  // and the measured tip position (crane frame, NaN when there is no valid measurement).
  // Sources in operator coordinates (a cylindrical joystick mapping) need the tip to turn their
  // axes into the crane frame; scripted sources use the clock. Default: ignored.
  virtual void begin_cycle(double now_s, const Eigen::Vector3d& tip_m) noexcept {
    (void)now_s;
    (void)tip_m;
  }
  // Short static name for logs and telemetry: "keyboard", "evdev", "sdl", "dds", "replay".
  virtual const char* name() const noexcept = 0;
};

}  // namespace craneassist::input
