#include "craneassist/input/keyboard.hpp"

#include <algorithm>

namespace craneassist::input {

const char* to_string(Key key) {
  switch (key) {
    case Key::kNone:
      return "none";
    case Key::kForward:
      return "forward";
    case Key::kBack:
      return "back";
    case Key::kLeft:
      return "left";
    case Key::kRight:
      return "right";
    case Key::kUp:
      return "up";
    case Key::kDown:
      return "down";
    case Key::kDriveForward:
      return "drive_forward";
    case Key::kDriveBack:
      return "drive_back";
    case Key::kSteerLeft:
      return "steer_left";
    case Key::kSteerRight:
      return "steer_right";
    case Key::kDeadman:
      return "deadman";
    case Key::kFaster:
      return "faster";
    case Key::kSlower:
      return "slower";
    case Key::kLatch:
      return "latch";
    case Key::kStopAll:
      return "stop_all";
    case Key::kQuit:
      return "quit";
  }
  return "unknown";
}

Key KeyDecoder::feed(std::uint8_t byte) noexcept {
  if (len_ == 0) {
    switch (byte) {
      case 0x1b:
        seq_[len_++] = byte;
        return Key::kNone;
      case 'w':
      case 'W':
        return Key::kForward;
      case 's':
      case 'S':
        return Key::kBack;
      case 'a':
      case 'A':
        return Key::kLeft;
      case 'd':
      case 'D':
        return Key::kRight;
      case 'r':
      case 'R':
        return Key::kUp;
      case 'f':
      case 'F':
        return Key::kDown;
      case 'i':
      case 'I':
        return Key::kDriveForward;
      case 'k':
      case 'K':
        return Key::kDriveBack;
      case 'u':
      case 'U':
        return Key::kSteerLeft;
      case 'o':
      case 'O':
        return Key::kSteerRight;
      case ' ':
        return Key::kDeadman;
      case '+':
      case '=':
        return Key::kFaster;
      case '-':
      case '_':
        return Key::kSlower;
      case 'l':
      case 'L':
        return Key::kLatch;
      case 'x':
      case 'X':
        return Key::kStopAll;
      case 'q':
      case 'Q':
        return Key::kQuit;
      default:
        return Key::kNone;
    }
  }
  // Inside an escape sequence: ESC [ A..D (or ESC O A..D), ESC [ 5 ~, ESC [ 6 ~.
  seq_[len_++] = byte;
  if (len_ == 2) {
    if (byte == '[' || byte == 'O') return Key::kNone;
    len_ = 0;  // ESC followed by something else: drop both
    return Key::kNone;
  }
  if (len_ == 3) {
    Key key = Key::kNone;
    switch (byte) {
      case 'A':
        key = Key::kForward;
        break;
      case 'B':
        key = Key::kBack;
        break;
      case 'C':
        key = Key::kRight;
        break;
      case 'D':
        key = Key::kLeft;
        break;
      default:
        if (byte >= '0' && byte <= '9') return Key::kNone;  // ESC [ 5 ~ and the like
        break;
    }
    len_ = 0;
    return key;
  }
  // len_ >= 4: a parameter sequence, ends with '~' or after the buffer is full.
  if (byte == '~') {
    const std::uint8_t code = seq_[2];
    len_ = 0;
    if (code == '5') return Key::kUp;
    if (code == '6') return Key::kDown;
    return Key::kNone;
  }
  if (len_ >= seq_.size() || !((byte >= '0' && byte <= '9') || byte == ';')) len_ = 0;
  return Key::kNone;
}

void KeyboardState::press(std::size_t axis, int direction, double now_s) noexcept {
  Held& h = held_[axis];
  if (latched_) {
    h.direction = h.direction == -direction ? 0 : direction;  // the opposite key cancels
    return;
  }
  if (h.direction == direction && now_s <= h.until_s) {
    h.until_s = std::max(h.until_s, now_s + settings_.repeat_hold_s);  // an auto-repeat
  } else {
    h.direction = direction;
    h.first_s = now_s;
    h.until_s = now_s + settings_.first_hold_s;
  }
}

void KeyboardState::on_key(Key key, double now_s) noexcept {
  switch (key) {
    case Key::kLeft:
      press(0, -1, now_s);
      break;
    case Key::kRight:
      press(0, 1, now_s);
      break;
    case Key::kForward:
      press(1, 1, now_s);
      break;
    case Key::kBack:
      press(1, -1, now_s);
      break;
    case Key::kUp:
      press(2, 1, now_s);
      break;
    case Key::kDown:
      press(2, -1, now_s);
      break;
    case Key::kDriveForward:
      press(3, 1, now_s);
      break;
    case Key::kDriveBack:
      press(3, -1, now_s);
      break;
    case Key::kSteerLeft:
      press(4, 1, now_s);
      break;
    case Key::kSteerRight:
      press(4, -1, now_s);
      break;
    case Key::kDeadman:
      deadman_ = !deadman_;
      break;
    case Key::kFaster:
      if (step_ < kSteps) ++step_;
      break;
    case Key::kSlower:
      if (step_ > 1) --step_;
      break;
    case Key::kLatch:
      latched_ = !latched_;
      held_ = {};
      break;
    case Key::kStopAll:
      held_ = {};
      break;
    case Key::kQuit:
      quit_ = true;
      held_ = {};
      break;
    case Key::kNone:
      break;
  }
}

bool KeyboardState::on(const Held& h, double now_s) const noexcept {
  return latched_ ? h.direction != 0 : now_s <= h.until_s;
}

Eigen::Vector3d KeyboardState::axes(double now_s) const noexcept {
  Eigen::Vector3d v;
  const double scale = static_cast<double>(step_) / kSteps;
  for (std::size_t i = 0; i < 3; ++i) {
    const Held& h = held_[i];
    v[static_cast<Eigen::Index>(i)] = on(h, now_s) ? h.direction * scale : 0.0;
  }
  return v;
}

Eigen::Vector2d KeyboardState::drive(double now_s) const noexcept {
  Eigen::Vector2d d;
  const double scale = static_cast<double>(step_) / kSteps;
  for (std::size_t i = 0; i < 2; ++i) {
    const Held& h = held_[3 + i];
    d[static_cast<Eigen::Index>(i)] = on(h, now_s) ? h.direction * scale : 0.0;
  }
  return d;
}

}  // namespace craneassist::input
