#include "craneassist/input/evdev_source.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <libevdev/libevdev.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

namespace craneassist::input {
namespace {

bool button_for(unsigned code, GamepadButton& out) {
  switch (code) {
    case BTN_SOUTH:
      out = GamepadButton::kA;
      return true;
    case BTN_EAST:
      out = GamepadButton::kB;
      return true;
    case BTN_NORTH:  // xpad reports the X button as BTN_X (== BTN_NORTH)
      out = GamepadButton::kX;
      return true;
    case BTN_WEST:  // and Y as BTN_Y (== BTN_WEST)
      out = GamepadButton::kY;
      return true;
    case BTN_SELECT:
      out = GamepadButton::kBack;
      return true;
    case BTN_MODE:
      out = GamepadButton::kGuide;
      return true;
    case BTN_START:
      out = GamepadButton::kStart;
      return true;
    case BTN_THUMBL:
      out = GamepadButton::kLeftStick;
      return true;
    case BTN_THUMBR:
      out = GamepadButton::kRightStick;
      return true;
    case BTN_TL:
      out = GamepadButton::kLeftShoulder;
      return true;
    case BTN_TR:
      out = GamepadButton::kRightShoulder;
      return true;
    case BTN_DPAD_UP:
      out = GamepadButton::kDpadUp;
      return true;
    case BTN_DPAD_DOWN:
      out = GamepadButton::kDpadDown;
      return true;
    case BTN_DPAD_LEFT:
      out = GamepadButton::kDpadLeft;
      return true;
    case BTN_DPAD_RIGHT:
      out = GamepadButton::kDpadRight;
      return true;
    default:
      return false;
  }
}

}  // namespace

EvdevDecoder::EvdevDecoder() {
  ranges_[ABS_Z] = {0, 1023};
  ranges_[ABS_RZ] = {0, 1023};
  ranges_[ABS_HAT0X] = {-1, 1};
  ranges_[ABS_HAT0Y] = {-1, 1};
}

void EvdevDecoder::set_range(unsigned code, int min, int max) noexcept {
  if (code < ranges_.size() && max > min) ranges_[code] = {min, max};
}

void EvdevDecoder::reset() noexcept {
  pending_ = {};
  state_ = {};
  dropped_ = false;
}

bool EvdevDecoder::feed(const input_event& ev) noexcept {
  if (ev.type == EV_SYN) {
    if (ev.code == SYN_DROPPED) {
      dropped_ = true;
      return false;
    }
    if (ev.code == SYN_REPORT) {
      if (dropped_) {  // the frame after a drop is incomplete: wait for the next one
        dropped_ = false;
        pending_ = state_;
        return false;
      }
      state_ = pending_;
      return true;
    }
    return false;
  }
  if (dropped_) return false;
  if (ev.type == EV_KEY) {
    GamepadButton b;
    if (button_for(ev.code, b)) pending_.set_button(b, ev.value != 0);
    return false;
  }
  if (ev.type != EV_ABS || ev.code >= ranges_.size()) return false;
  const Range& r = ranges_[ev.code];
  const double u = std::clamp(static_cast<double>(ev.value - r.min) / (r.max - r.min), 0.0, 1.0);
  const double stick = 2.0 * u - 1.0;
  switch (ev.code) {
    case ABS_X:
      pending_.set_axis(GamepadAxis::kLeftX, stick);
      break;
    case ABS_Y:
      pending_.set_axis(GamepadAxis::kLeftY, stick);
      break;
    case ABS_RX:
      pending_.set_axis(GamepadAxis::kRightX, stick);
      break;
    case ABS_RY:
      pending_.set_axis(GamepadAxis::kRightY, stick);
      break;
    case ABS_Z:
      pending_.set_axis(GamepadAxis::kLeftTrigger, u);
      break;
    case ABS_RZ:
      pending_.set_axis(GamepadAxis::kRightTrigger, u);
      break;
    case ABS_HAT0X:
      pending_.set_button(GamepadButton::kDpadLeft, ev.value < 0);
      pending_.set_button(GamepadButton::kDpadRight, ev.value > 0);
      break;
    case ABS_HAT0Y:
      pending_.set_button(GamepadButton::kDpadUp, ev.value < 0);
      pending_.set_button(GamepadButton::kDpadDown, ev.value > 0);
      break;
    default:
      break;
  }
  return false;
}

namespace {

class LibevdevReader : public EventReader {
 public:
  LibevdevReader(int fd, libevdev* dev) : fd_(fd), dev_(dev) {}
  ~LibevdevReader() override {
    libevdev_free(dev_);
    ::close(fd_);
  }

  Result next(input_event& ev, int timeout_ms) override {
    for (;;) {
      const int flag = syncing_ ? LIBEVDEV_READ_FLAG_SYNC : LIBEVDEV_READ_FLAG_NORMAL;
      const int rc = libevdev_next_event(dev_, flag, &ev);
      if (rc == LIBEVDEV_READ_STATUS_SUCCESS) return Result::kEvent;
      if (rc == LIBEVDEV_READ_STATUS_SYNC) {
        // Resynchronising after a drop: hand on the sync events (the decoder rebuilds state).
        syncing_ = true;
        return Result::kEvent;
      }
      if (rc == -EAGAIN) {
        if (syncing_) {
          syncing_ = false;
          continue;
        }
        struct pollfd p = {fd_, POLLIN, 0};
        const int ready = ::poll(&p, 1, timeout_ms);
        if (ready == 0 || (ready < 0 && errno == EINTR)) return Result::kNone;
        if (ready < 0 || (p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) return Result::kGone;
        timeout_ms = 0;
        continue;
      }
      return Result::kGone;  // -ENODEV (unplugged) or another read error
    }
  }

  void configure(EvdevDecoder& decoder) override {
    for (unsigned code : {ABS_X, ABS_Y, ABS_RX, ABS_RY, ABS_Z, ABS_RZ, ABS_HAT0X, ABS_HAT0Y}) {
      const input_absinfo* info = libevdev_get_abs_info(dev_, code);
      if (info != nullptr) decoder.set_range(code, info->minimum, info->maximum);
    }
    // The present state, as if the device had just reported it.
    input_event ev{};
    for (unsigned type : {EV_ABS, EV_KEY}) {
      const unsigned max = type == EV_ABS ? ABS_MAX : KEY_MAX;
      for (unsigned code = 0; code <= max; ++code) {
        if (!libevdev_has_event_code(dev_, type, code)) continue;
        ev.type = static_cast<__u16>(type);
        ev.code = static_cast<__u16>(code);
        ev.value = libevdev_get_event_value(dev_, type, code);
        decoder.feed(ev);
      }
    }
    ev.type = EV_SYN;
    ev.code = SYN_REPORT;
    ev.value = 0;
    decoder.feed(ev);
  }

  std::string name() const override {
    const char* n = libevdev_get_name(dev_);
    return n != nullptr ? n : "";
  }

 private:
  int fd_;
  libevdev* dev_;
  bool syncing_ = false;
};

std::unique_ptr<EventReader> open_device(const std::string& path, const std::string& name_match,
                                         bool any_gamepad) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return nullptr;
  libevdev* dev = nullptr;
  if (libevdev_new_from_fd(fd, &dev) < 0) {
    ::close(fd);
    return nullptr;
  }
  const char* n = libevdev_get_name(dev);
  const std::string dev_name = n != nullptr ? n : "";
  const bool gamepad = libevdev_has_event_code(dev, EV_ABS, ABS_X) &&
                       libevdev_has_event_code(dev, EV_ABS, ABS_Y) &&
                       libevdev_has_event_code(dev, EV_KEY, BTN_SOUTH);
  const bool ok = any_gamepad          ? gamepad
                  : name_match.empty() ? true
                                       : dev_name.find(name_match) != std::string::npos;
  if (!ok) {
    libevdev_free(dev);
    ::close(fd);
    return nullptr;
  }
  return std::make_unique<LibevdevReader>(fd, dev);
}

}  // namespace

EventReaderOpener libevdev_opener(std::string path, std::string name_match) {
  return [path, name_match]() -> std::unique_ptr<EventReader> {
    if (!path.empty()) return open_device(path, "", false);
    DIR* dir = ::opendir("/dev/input");
    if (dir == nullptr) return nullptr;
    std::vector<std::string> candidates;
    while (const dirent* e = ::readdir(dir)) {
      if (std::strncmp(e->d_name, "event", 5) == 0) {
        candidates.push_back(std::string("/dev/input/") + e->d_name);
      }
    }
    ::closedir(dir);
    std::sort(candidates.begin(), candidates.end());
    for (const auto& c : candidates) {
      auto reader = open_device(c, name_match, name_match.empty());
      if (reader) return reader;
    }
    return nullptr;
  };
}

EvdevSource::EvdevSource(const JoystickMapping& mapping, EventReaderOpener opener,
                         const Options& options)
    : DevicePadSource(mapping), opener_(std::move(opener)), options_(options) {
  if (options_.own_thread) start_reader();
}

EvdevSource::~EvdevSource() {
  stop_reader();
}

void EvdevSource::service() {
  const double now = steady_now_s();
  if (!reader_) {
    if (now >= next_open_s_) {
      next_open_s_ = now + options_.reopen_interval_s;
      ++open_attempts_;
      reader_ = opener_();
      if (reader_) {
        decoder_.reset();
        reader_->configure(decoder_);  // ranges and the present state
        published_ = {};
        published_.pad = decoder_.state();
        published_.has_state = true;
        published_.connected = true;
        published_.stamp_s = steady_now_s();
        latest_.publish(published_);
        return;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(options_.wait_ms));
    return;
  }
  input_event ev{};
  int wait = options_.wait_ms;
  for (int i = 0; i < 256; ++i) {  // drain what is there, bounded
    const EventReader::Result r = reader_->next(ev, wait);
    wait = 0;
    if (r == EventReader::Result::kNone) break;
    if (r == EventReader::Result::kGone) {
      reader_.reset();
      next_open_s_ = steady_now_s() + options_.reopen_interval_s;
      published_ = {};
      published_.connected = false;
      published_.stamp_s = steady_now_s();
      latest_.publish(published_);
      return;
    }
    if (decoder_.feed(ev)) {
      published_.pad = decoder_.state();
      published_.has_state = true;
    }
  }
  // The state is confirmed now, events or not (a stick held still sends nothing).
  published_.stamp_s = steady_now_s();
  latest_.publish(published_);
}

}  // namespace craneassist::input
