#include "craneassist/can/socketcan.hpp"

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace craneassist::can {

const char* to_string(SendStatus status) {
  switch (status) {
    case SendStatus::kOk:
      return "ok";
    case SendStatus::kQueueFull:
      return "transmit queue full";
    case SendStatus::kError:
      return "send failed";
  }
  return "?";
}

TimestampUs realtime_now_us() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<TimestampUs>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}

namespace {

[[noreturn]] void fail(const std::string& iface, const char* what) {
  throw std::runtime_error("CAN interface '" + iface + "': " + what + ": " + std::strerror(errno));
}

}  // namespace

SocketCanTransport::SocketCanTransport(const std::string& interface_name) : name_(interface_name) {
  if (name_.empty() || name_.size() >= IFNAMSIZ) {
    throw std::runtime_error("CAN interface '" + name_ + "': bad interface name");
  }
  fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd_ < 0) fail(name_, "socket(PF_CAN) (does this kernel have CAN?)");
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, name_.c_str(), IFNAMSIZ - 1);
  if (::ioctl(fd_, SIOCGIFINDEX, &ifr) < 0) {
    ::close(fd_);
    fail(name_, "no such interface");
  }
  const can_err_mask_t err_mask = CAN_ERR_BUSOFF | CAN_ERR_CRTL | CAN_ERR_RESTARTED | CAN_ERR_PROT |
                                  CAN_ERR_ACK | CAN_ERR_BUSERROR;
  const int on = 1;
  if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) < 0 ||
      ::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on) < 0) {
    ::close(fd_);
    fail(name_, "setsockopt");
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
    ::close(fd_);
    fail(name_, "bind");
  }
}

SocketCanTransport::~SocketCanTransport() {
  if (fd_ >= 0) ::close(fd_);
}

SendStatus SocketCanTransport::send(const CanFrame& frame) {
  can_frame raw{};
  raw.can_id =
      frame.extended ? ((frame.id & CAN_EFF_MASK) | CAN_EFF_FLAG) : (frame.id & CAN_SFF_MASK);
  raw.len = frame.dlc > 8 ? 8 : frame.dlc;
  std::memcpy(raw.data, frame.data.data(), raw.len);
  const ssize_t n = ::write(fd_, &raw, sizeof raw);
  if (n == static_cast<ssize_t>(sizeof raw)) return SendStatus::kOk;
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS)) {
    return SendStatus::kQueueFull;
  }
  return SendStatus::kError;
}

void SocketCanTransport::receive(Received& out) {
  can_frame raw{};
  iovec iov{&raw, sizeof raw};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timeval)) + 64];
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
  out.bus_error = kBusErrorNone;
  if (n < 0) {
    out.kind = (errno == EAGAIN || errno == EWOULDBLOCK) ? ReceiveKind::kNone : ReceiveKind::kError;
    return;
  }
  out.timestamp_us = 0;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMP) {
      timeval tv{};
      std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
      out.timestamp_us = static_cast<TimestampUs>(tv.tv_sec) * 1000000 + tv.tv_usec;
    }
  }
  if (out.timestamp_us == 0) out.timestamp_us = realtime_now_us();
  if (n != static_cast<ssize_t>(sizeof raw)) {
    out.kind = ReceiveKind::kUnsupported;  // CAN FD or truncated
    return;
  }
  if ((raw.can_id & CAN_ERR_FLAG) != 0) {
    std::uint32_t flags = kBusErrorNone;
    if ((raw.can_id & CAN_ERR_BUSOFF) != 0) flags |= kBusOff;
    if ((raw.can_id & CAN_ERR_RESTARTED) != 0) flags |= kControllerRestarted;
    if ((raw.can_id & CAN_ERR_CRTL) != 0) {
      if ((raw.data[1] & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0) {
        flags |= kErrorPassive;
      }
      if ((raw.data[1] & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0) {
        flags |= kErrorWarning;
      }
    }
    if ((raw.can_id & (CAN_ERR_PROT | CAN_ERR_ACK | CAN_ERR_BUSERROR)) != 0) {
      flags |= kBusErrorOther;
    }
    out.kind = ReceiveKind::kBusError;
    out.bus_error = flags;
    return;
  }
  if ((raw.can_id & CAN_RTR_FLAG) != 0) {
    out.kind = ReceiveKind::kUnsupported;
    return;
  }
  out.frame.extended = (raw.can_id & CAN_EFF_FLAG) != 0;
  out.frame.id = raw.can_id & (out.frame.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
  out.frame.dlc = raw.len > 8 ? 8 : raw.len;
  std::memcpy(out.frame.data.data(), raw.data, 8);
  out.kind = ReceiveKind::kFrame;
}

bool SocketCanTransport::wait_readable(int timeout_ms) {
  pollfd p{fd_, POLLIN, 0};
  return ::poll(&p, 1, timeout_ms) > 0;
}

}  // namespace craneassist::can
