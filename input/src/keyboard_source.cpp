#include "craneassist/input/keyboard_source.hpp"

#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>

namespace craneassist::input {
namespace {

// The saved terminal state, for restore_terminal() from a signal handler.
struct termios g_saved;
std::atomic<int> g_saved_fd{-1};

}  // namespace

void KeyboardSource::restore_terminal() noexcept {
  const int fd = g_saved_fd.load();
  if (fd >= 0) tcsetattr(fd, TCSANOW, &g_saved);
}

KeyboardSource::KeyboardSource(int fd, const JoystickMapping& mapping,
                               const KeyboardSettings& settings, std::atomic<bool>* quit)
    : fd_(fd),
      mapping_(mapping),
      frame_(mapping.frame, mapping.slew, mapping.min_radius_m),
      state_(settings),
      quit_(quit) {
  struct termios t;
  if (!isatty(fd) || tcgetattr(fd, &t) != 0) {
    throw std::runtime_error("the keyboard input needs a terminal on stdin");
  }
  g_saved = t;
  g_saved_fd.store(fd);
  t.c_lflag &= static_cast<tcflag_t>(~(ICANON | ECHO));
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (tcsetattr(fd, TCSANOW, &t) != 0) {
    g_saved_fd.store(-1);
    throw std::runtime_error("cannot put the terminal in raw mode");
  }
  step_.store(state_.speed_step());
}

KeyboardSource::~KeyboardSource() {
  restore_terminal();
  g_saved_fd.store(-1);
}

void KeyboardSource::begin_cycle(double /*now_s*/, const Eigen::Vector3d& tip_m) noexcept {
  tip_ = tip_m;
}

SourceState KeyboardSource::poll(OperatorCommand& out) noexcept {
  if (gone_) return SourceState::kDisconnected;
  const double now = input::steady_now_s();
  for (int rounds = 0; rounds < 8; ++rounds) {  // bounded: at most 8 x 64 bytes per cycle
    struct pollfd p = {fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, 0);
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) break;
    if ((p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0 && (p.revents & POLLIN) == 0) {
      gone_ = true;
      return SourceState::kDisconnected;
    }
    unsigned char buf[64];
    const ssize_t n = ::read(fd_, buf, sizeof buf);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) break;
    if (n <= 0) {  // readable but nothing: end of file (terminal closed)
      gone_ = true;
      return SourceState::kDisconnected;
    }
    for (ssize_t i = 0; i < n; ++i) state_.on_key(decoder_.feed(buf[i]), now);
  }
  if (state_.quit() && quit_ != nullptr) quit_->store(true);
  step_.store(state_.speed_step(), std::memory_order_relaxed);
  latched_.store(state_.latched(), std::memory_order_relaxed);

  const Eigen::Vector3d axes = state_.axes(now);
  Eigen::Vector3d op;
  for (std::size_t i = 0; i < kOperatorAxisCount; ++i) {
    const AxisShape& s = mapping_.axes[i];
    op[static_cast<Eigen::Index>(i)] = s.enabled ? axes[static_cast<Eigen::Index>(i)] * s.max : 0.0;
  }
  out.v_m_s = frame_.to_crane(op, tip_);
  out.deadman = state_.deadman();
  out.drive = state_.drive(now);
  out.stamp_s = now;
  return SourceState::kOk;
}

}  // namespace craneassist::input
