// The evdev joystick: input_event sequences through the decoder, and the source on fake devices
// (connect, mapping, ENODEV -> disconnected, rate-limited re-open, re-attach). With a writable
// /dev/uinput a virtual gamepad also goes through libevdev end to end.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/uinput.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>

#include "craneassist/input/evdev_source.hpp"

using namespace craneassist::input;

namespace {

input_event ev(unsigned type, unsigned code, int value) {
  input_event e{};
  e.type = static_cast<__u16>(type);
  e.code = static_cast<__u16>(code);
  e.value = value;
  return e;
}
input_event syn() {
  return ev(EV_SYN, SYN_REPORT, 0);
}

// A device the test scripts: a queue of events, and "unplugged" (ENODEV on the next read).
struct FakeDevice {
  std::mutex mutex;
  std::deque<input_event> events;
  bool unplugged = false;
  bool present = true;
  int opened = 0;
};

class FakeReader : public EventReader {
 public:
  explicit FakeReader(std::shared_ptr<FakeDevice> d) : d_(std::move(d)) {}
  Result next(input_event& e, int /*timeout_ms*/) override {
    std::lock_guard<std::mutex> lock(d_->mutex);
    if (d_->unplugged) return Result::kGone;
    if (d_->events.empty()) return Result::kNone;
    e = d_->events.front();
    d_->events.pop_front();
    return Result::kEvent;
  }
  void configure(EvdevDecoder& decoder) override {
    decoder.set_range(ABS_X, -100, 100);
    decoder.set_range(ABS_Y, -100, 100);
  }
  std::string name() const override { return "fake pad"; }

 private:
  std::shared_ptr<FakeDevice> d_;
};

EventReaderOpener fake_opener(std::shared_ptr<FakeDevice> d) {
  return [d]() -> std::unique_ptr<EventReader> {
    std::lock_guard<std::mutex> lock(d->mutex);
    if (!d->present) return nullptr;
    d->unplugged = false;
    ++d->opened;
    return std::make_unique<FakeReader>(d);
  };
}

void push(FakeDevice& d, std::initializer_list<input_event> events) {
  std::lock_guard<std::mutex> lock(d.mutex);
  for (const auto& e : events) d.events.push_back(e);
}

}  // namespace

TEST(EvdevDecoder, XpadLayoutToGamepadState) {
  EvdevDecoder d;
  EXPECT_FALSE(d.feed(ev(EV_ABS, ABS_X, 32767)));
  EXPECT_FALSE(d.feed(ev(EV_ABS, ABS_RY, -32768)));
  EXPECT_FALSE(d.feed(ev(EV_ABS, ABS_RZ, 1023)));
  EXPECT_FALSE(d.feed(ev(EV_KEY, BTN_TR, 1)));
  EXPECT_FALSE(d.feed(ev(EV_ABS, ABS_HAT0Y, -1)));
  EXPECT_EQ(d.state().axis(GamepadAxis::kLeftX), 0.0);  // nothing applies before SYN_REPORT
  EXPECT_TRUE(d.feed(syn()));
  EXPECT_NEAR(d.state().axis(GamepadAxis::kLeftX), 1.0, 1e-12);
  EXPECT_NEAR(d.state().axis(GamepadAxis::kRightY), -1.0, 1e-12);
  EXPECT_NEAR(d.state().axis(GamepadAxis::kRightTrigger), 1.0, 1e-12);
  EXPECT_TRUE(d.state().button(GamepadButton::kRightShoulder));
  EXPECT_TRUE(d.state().button(GamepadButton::kDpadUp));
  d.feed(ev(EV_KEY, BTN_TR, 0));
  d.feed(ev(EV_ABS, ABS_X, 0));
  d.feed(syn());
  EXPECT_FALSE(d.state().button(GamepadButton::kRightShoulder));
  EXPECT_NEAR(d.state().axis(GamepadAxis::kLeftX), 0.5 / 32767.5, 1e-9);
}

TEST(EvdevDecoder, RangesClampingAndSynDropped) {
  EvdevDecoder d;
  d.set_range(ABS_Y, 0, 255);
  d.feed(ev(EV_ABS, ABS_Y, 255));
  d.feed(ev(EV_ABS, ABS_X, 99999));  // beyond the range: clamped
  d.feed(syn());
  EXPECT_NEAR(d.state().axis(GamepadAxis::kLeftY), 1.0, 1e-12);
  EXPECT_NEAR(d.state().axis(GamepadAxis::kLeftX), 1.0, 1e-12);
  // After SYN_DROPPED the partial frame is thrown away, up to and including its SYN_REPORT.
  d.feed(ev(EV_SYN, SYN_DROPPED, 0));
  d.feed(ev(EV_ABS, ABS_Y, 0));
  EXPECT_FALSE(d.feed(syn()));
  EXPECT_NEAR(d.state().axis(GamepadAxis::kLeftY), 1.0, 1e-12);
  d.feed(ev(EV_ABS, ABS_Y, 0));
  EXPECT_TRUE(d.feed(syn()));
  EXPECT_NEAR(d.state().axis(GamepadAxis::kLeftY), -1.0, 1e-12);
  d.feed(ev(EV_KEY, KEY_A, 1));  // unknown codes are ignored
  d.feed(ev(EV_REL, REL_X, 5));
  EXPECT_TRUE(d.feed(syn()));
}

TEST(EvdevSource, MapsTheDeviceAndReportsUnplugAndReturn) {
  auto dev = std::make_shared<FakeDevice>();
  EvdevSource::Options o;
  o.own_thread = false;
  o.wait_ms = 1;
  o.reopen_interval_s = 0.05;
  EvdevSource source(default_gamepad_mapping(), fake_opener(dev), o);
  OperatorCommand c;
  EXPECT_EQ(source.poll(c), SourceState::kDisconnected);  // not opened yet

  source.service();  // opens
  ASSERT_EQ(dev->opened, 1);
  EXPECT_EQ(source.poll(c), SourceState::kOk);  // the present state: centred, released
  EXPECT_TRUE(c.v_m_s.isZero());
  EXPECT_FALSE(c.deadman);

  push(*dev, {ev(EV_ABS, ABS_Y, -100), ev(EV_KEY, BTN_TR, 1), syn()});
  source.service();
  source.begin_cycle(0.0, {4.0, 1.0, 0.0});
  ASSERT_EQ(source.poll(c), SourceState::kOk);
  EXPECT_TRUE(c.deadman);
  EXPECT_TRUE(c.v_m_s.isApprox(Eigen::Vector3d(0.5, 0.0, 0.0), 1e-12)) << c.v_m_s.transpose();
  // A stick held still sends nothing, but the reader renews the stamp.
  const double stamp = c.stamp_s;
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  source.service();
  source.poll(c);
  EXPECT_GT(c.stamp_s, stamp);

  // Unplugged: ENODEV -> disconnected; no re-open before the interval.
  {
    std::lock_guard<std::mutex> lock(dev->mutex);
    dev->unplugged = true;
    dev->present = false;
  }
  source.service();
  EXPECT_EQ(source.poll(c), SourceState::kDisconnected);
  const int attempts = source.open_attempts();
  source.service();
  EXPECT_EQ(source.open_attempts(), attempts);  // rate-limited
  std::this_thread::sleep_for(std::chrono::milliseconds(60));
  source.service();
  EXPECT_EQ(source.open_attempts(), attempts + 1);  // tried, device still absent
  EXPECT_EQ(source.poll(c), SourceState::kDisconnected);

  // Plugged back in: re-opened, state from scratch (deadman released).
  {
    std::lock_guard<std::mutex> lock(dev->mutex);
    dev->present = true;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(60));
  source.service();
  EXPECT_EQ(dev->opened, 2);
  ASSERT_EQ(source.poll(c), SourceState::kOk);
  EXPECT_FALSE(c.deadman);
}

TEST(EvdevSource, ReaderThreadHandsOverWithoutBlockingTheLoop) {
  auto dev = std::make_shared<FakeDevice>();
  EvdevSource::Options o;
  o.wait_ms = 2;
  EvdevSource source(default_gamepad_mapping(), fake_opener(dev), o);
  push(*dev, {ev(EV_ABS, ABS_RY, -32768), ev(EV_KEY, BTN_TR, 1), syn()});
  OperatorCommand c;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (!(source.poll(c) == SourceState::kOk && c.deadman) &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(c.deadman);
  EXPECT_NEAR(c.v_m_s.y(), 0.4, 1e-12);
}

// End to end through the kernel when the machine has uinput (not in most containers).
TEST(EvdevSource, UinputVirtualGamepad) {
  const int fd = ::open("/dev/uinput", O_WRONLY | O_NONBLOCK);
  if (fd < 0) {
    GTEST_SKIP() << "/dev/uinput is missing or not writable here (" << std::strerror(errno)
                 << "): the decoder and the source are tested above on fake devices";
  }
  ioctl(fd, UI_SET_EVBIT, EV_KEY);
  ioctl(fd, UI_SET_KEYBIT, BTN_SOUTH);
  ioctl(fd, UI_SET_KEYBIT, BTN_TR);
  ioctl(fd, UI_SET_EVBIT, EV_ABS);
  for (int code : {ABS_X, ABS_Y, ABS_RX, ABS_RY}) {
    uinput_abs_setup abs{};
    abs.code = static_cast<__u16>(code);
    abs.absinfo.minimum = -32768;
    abs.absinfo.maximum = 32767;
    ioctl(fd, UI_ABS_SETUP, &abs);
  }
  uinput_setup setup{};
  std::strcpy(setup.name, "craneassist test pad");
  setup.id.bustype = BUS_VIRTUAL;
  ioctl(fd, UI_DEV_SETUP, &setup);
  ASSERT_EQ(ioctl(fd, UI_DEV_CREATE), 0);
  auto emit = [fd](unsigned type, unsigned code, int value) {
    input_event e = ev(type, code, value);
    ASSERT_EQ(::write(fd, &e, sizeof e), static_cast<ssize_t>(sizeof e));
  };

  EvdevSource::Options o;
  o.reopen_interval_s = 0.1;
  EvdevSource source(default_gamepad_mapping(), libevdev_opener("", "craneassist test pad"), o);
  OperatorCommand c;
  auto wait_for = [&](auto pred) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
    while (!pred() && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return pred();
  };
  ASSERT_TRUE(wait_for([&] { return source.poll(c) == SourceState::kOk; }));
  emit(EV_ABS, ABS_Y, -32768);
  emit(EV_KEY, BTN_TR, 1);
  emit(EV_SYN, SYN_REPORT, 0);
  source.begin_cycle(0.0, {4.0, 1.0, 0.0});
  ASSERT_TRUE(wait_for([&] { return source.poll(c) == SourceState::kOk && c.deadman; }));
  EXPECT_NEAR(c.v_m_s.x(), 0.5, 1e-3);
  ioctl(fd, UI_DEV_DESTROY);
  ::close(fd);
  EXPECT_TRUE(wait_for([&] { return source.poll(c) == SourceState::kDisconnected; }));
}

TEST(EvdevSource, LibevdevOpenerRejectsWhatIsNotAnInputDevice) {
  EXPECT_EQ(libevdev_opener("/nonexistent/event0", "")(), nullptr);
  EXPECT_EQ(libevdev_opener("/dev/null", "")(), nullptr);  // opens, but no evdev ioctls
  // A name nothing has: scans /dev/input (if any) and finds nothing.
  EXPECT_EQ(libevdev_opener("", "no such craneassist pad")(), nullptr);
  // The source keeps reporting a disconnected device and keeps trying, at the bounded rate.
  EvdevSource::Options o;
  o.own_thread = false;
  o.wait_ms = 1;
  o.reopen_interval_s = 0.02;
  EvdevSource source(default_gamepad_mapping(), libevdev_opener("/dev/null", ""), o);
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < std::chrono::milliseconds(100)) {
    source.service();
  }
  OperatorCommand c;
  EXPECT_EQ(source.poll(c), SourceState::kDisconnected);
  EXPECT_GE(source.open_attempts(), 3);
  EXPECT_LE(source.open_attempts(), 7);  // 100 ms / 20 ms, plus the first
}
