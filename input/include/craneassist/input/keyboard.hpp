// The virtual joystick's logic, without the terminal: bytes from a terminal -> keys -> the held
// operator axes. Terminals send no key-up events, only the key again at the auto-repeat rate, so
// a key counts as held for first_hold after its first press (long enough to bridge the
// auto-repeat delay, typically 250-600 ms) and for repeat_hold after each repeat; in latched mode
// a press sets the axis until the opposite key or the stop key. docs/joystick.md has the keys.
// Allocation-free and exception-free.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>

namespace craneassist::input {

enum class Key {
  kNone,
  kForward,       // w, up arrow: reach out
  kBack,          // s, down arrow: reach in
  kLeft,          // a, left arrow: slew left
  kRight,         // d, right arrow: slew right
  kUp,            // r, page up: tip up
  kDown,          // f, page down: tip down
  kDriveForward,  // i: drive forward (sim --base)
  kDriveBack,     // k: drive back
  kSteerLeft,     // u: steer left
  kSteerRight,    // o: steer right
  kDeadman,       // space: toggle the enable
  kFaster,        // + or =
  kSlower,        // - or _
  kLatch,         // l: latched mode on/off
  kStopAll,       // x: all axes to zero (latched mode)
  kQuit,          // q, Q
};
const char* to_string(Key key);

// Splits terminal input into keys (arrows and page keys arrive as escape sequences, possibly
// split across reads).
class KeyDecoder {
 public:
  // Feeds one byte; returns the completed key or kNone (partial sequence, unknown byte).
  Key feed(std::uint8_t byte) noexcept;

 private:
  std::array<std::uint8_t, 8> seq_{};
  std::size_t len_ = 0;
};

struct KeyboardSettings {
  double first_hold_s = 0.55;   // a single press holds the axis this long
  double repeat_hold_s = 0.15;  // each auto-repeat extends it by this much
};

class KeyboardState {
 public:
  explicit KeyboardState(const KeyboardSettings& settings) noexcept : settings_(settings) {}

  void on_key(Key key, double now_s) noexcept;
  // Operator axes (lateral, radial, vertical) in -1..1 times the speed step, at time now_s.
  Eigen::Vector3d axes(double now_s) const noexcept;
  // The drive keys (speed, curvature; curvature positive: left) in -1..1 times the speed step.
  Eigen::Vector2d drive(double now_s) const noexcept;
  bool deadman() const noexcept { return deadman_; }
  bool latched() const noexcept { return latched_; }
  bool quit() const noexcept { return quit_; }
  // The speed step, 1..kSteps; the axes are scaled by step / kSteps.
  int speed_step() const noexcept { return step_; }
  static constexpr int kSteps = 4;

 private:
  struct Held {
    int direction = 0;  // -1, 0, +1
    double first_s = -1e9;
    double until_s = -1e9;
  };
  void press(std::size_t axis, int direction, double now_s) noexcept;

  KeyboardSettings settings_;
  bool on(const Held& h, double now_s) const noexcept;

  std::array<Held, 5> held_{};  // lateral, radial, vertical; drive speed, curvature
  bool deadman_ = false;
  bool latched_ = false;
  bool quit_ = false;
  int step_ = 2;
};

}  // namespace craneassist::input
