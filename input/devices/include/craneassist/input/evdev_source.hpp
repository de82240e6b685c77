// Physical joysticks through Linux evdev (libevdev): a gamepad with the xpad (Xbox) layout, or
// any device whose axes and buttons use the same codes.
//
// EvdevDecoder turns input_event sequences into a GamepadState (pure, testable without a device).
// EvdevSource runs the device on a reader thread (device_pad_source.hpp): it opens the device (a
// path, a name match or the first gamepad), reads events non-blocking with a bounded wait, reports
// a device that returns ENODEV as disconnected and tries to re-open it at most every
// reopen_interval; the loop's poll() takes the latest state without waiting and maps it.
#pragma once

#include <linux/input.h>

#include <array>
#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "craneassist/input/device_pad_source.hpp"
#include "craneassist/input/gamepad.hpp"

namespace craneassist::input {

class EvdevDecoder {
 public:
  EvdevDecoder();
  // The range of an absolute axis (EVIOCGABS / libevdev_get_abs_info); defaults are the xpad's.
  void set_range(unsigned code, int min, int max) noexcept;
  // Feeds one event. Returns true when an EV_SYN/SYN_REPORT completes a frame: state() is then
  // the device's state. After SYN_DROPPED, events up to the next SYN_REPORT are discarded.
  bool feed(const input_event& ev) noexcept;
  const GamepadState& state() const noexcept { return state_; }
  void reset() noexcept;

 private:
  struct Range {
    int min = -32768, max = 32767;
  };
  std::array<Range, ABS_CNT> ranges_{};
  GamepadState pending_, state_;
  bool dropped_ = false;
};

// One opened device as the reader thread sees it (libevdev in production, fakes in tests).
class EventReader {
 public:
  enum class Result { kEvent, kNone, kGone };
  virtual ~EventReader() = default;
  // Waits at most timeout_ms for an event.
  virtual Result next(input_event& ev, int timeout_ms) = 0;
  // Sets the decoder's axis ranges from the device.
  virtual void configure(EvdevDecoder& decoder) = 0;
  virtual std::string name() const = 0;
};

// Opens a device: nullptr when there is none (yet). Called on the reader thread only.
using EventReaderOpener = std::function<std::unique_ptr<EventReader>()>;

// The libevdev opener: `path` if not empty, else the first /dev/input/event* whose name contains
// `name_match` (any gamepad-like device when empty: absolute X/Y and a south button).
EventReaderOpener libevdev_opener(std::string path, std::string name_match);

class EvdevSource : public DevicePadSource {
 public:
  struct Options {
    double reopen_interval_s = 0.5;
    int wait_ms = 20;        // the reader's bounded wait for events
    bool own_thread = true;  // false: the owner calls service() (tests)
  };
  EvdevSource(const JoystickMapping& mapping, EventReaderOpener opener, const Options& options);
  ~EvdevSource() override;

  const char* name() const noexcept override { return "evdev"; }

  // One round of the reader's work: an open attempt, or reading events for up to wait_ms.
  void service() override;
  int open_attempts() const noexcept { return open_attempts_.load(); }

 private:
  EventReaderOpener opener_;
  Options options_;
  // Reader thread state.
  std::unique_ptr<EventReader> reader_;
  EvdevDecoder decoder_;
  PadSnapshot published_;
  double next_open_s_ = 0.0;
  std::atomic<int> open_attempts_{0};
};

}  // namespace craneassist::input
