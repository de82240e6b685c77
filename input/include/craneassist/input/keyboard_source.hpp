// The virtual joystick: the keyboard of a terminal (works over ssh and in tmux) as a
// CommandSource. The terminal is put in raw mode (no line buffering, no echo; Ctrl-C still sends
// SIGINT) for the source's lifetime and restored by the destructor; restore_terminal() does it
// from a signal handler (async-signal-safe). poll() reads what is there without blocking (poll(2)
// with a zero timeout, then read(2)); end of file or a hang-up reports kDisconnected.
#pragma once

#include <termios.h>

#include <atomic>

#include "craneassist/input/command_source.hpp"
#include "craneassist/input/joystick_mapping.hpp"
#include "craneassist/input/keyboard.hpp"

namespace craneassist::input {

class KeyboardSource : public CommandSource {
 public:
  // fd: the terminal (stdin). Throws std::runtime_error when fd is not a terminal. The axes
  // use the mapping's frame and maximum speeds (full speed at the top speed step); quit, when
  // given, is set when q is pressed.
  KeyboardSource(int fd, const JoystickMapping& mapping, const KeyboardSettings& settings,
                 std::atomic<bool>* quit);
  ~KeyboardSource() override;
  KeyboardSource(const KeyboardSource&) = delete;
  KeyboardSource& operator=(const KeyboardSource&) = delete;

  void begin_cycle(double now_s, const Eigen::Vector3d& tip_m) noexcept override;
  SourceState poll(OperatorCommand& out) noexcept override;
  const char* name() const noexcept override { return "keyboard"; }

  // For the status line (any thread).
  int speed_step() const noexcept { return step_.load(std::memory_order_relaxed); }
  bool latched() const noexcept { return latched_.load(std::memory_order_relaxed); }

  // Restores the terminal state saved by the live source, if any (signal handlers, terminate).
  static void restore_terminal() noexcept;

 private:
  int fd_;
  JoystickMapping mapping_;
  OperatorFrame frame_;
  KeyDecoder decoder_;
  KeyboardState state_;
  std::atomic<bool>* quit_;
  Eigen::Vector3d tip_ = Eigen::Vector3d::UnitX();
  bool gone_ = false;
  std::atomic<int> step_{0};
  std::atomic<bool> latched_{false};
};

}  // namespace craneassist::input
