// Linux SocketCAN raw socket (PF_CAN, SOCK_RAW, CAN_RAW): non-blocking, kernel receive timestamps
// (SO_TIMESTAMP), error frames for bus-off and error-passive (CAN_RAW_ERR_FILTER). 11-bit and
// 29-bit identifiers. The receive buffers are members, so receive() allocates nothing.
#pragma once

#include <string>

#include "craneassist/can/transport.hpp"

namespace craneassist::can {

class SocketCanTransport final : public Transport {
 public:
  // Opens and binds a raw socket on the interface (e.g. "can0", "vcan0"). Throws
  // std::runtime_error naming the interface and the system error (no PF_CAN in the kernel,
  // unknown interface, ...).
  explicit SocketCanTransport(const std::string& interface_name);
  ~SocketCanTransport() override;
  SocketCanTransport(const SocketCanTransport&) = delete;
  SocketCanTransport& operator=(const SocketCanTransport&) = delete;

  SendStatus send(const CanFrame& frame) override;
  void receive(Received& out) override;
  bool wait_readable(int timeout_ms) override;
  const char* interface_name() const override { return name_.c_str(); }

 private:
  int fd_ = -1;
  std::string name_;
};

}  // namespace craneassist::can
