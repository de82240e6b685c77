// What the CAN backend and the emulator talk to: a non-blocking frame transport. SocketCanTransport
// (socketcan.hpp) is the real one; tests use an in-memory pair. Nothing here blocks or allocates.
#pragma once

#include <cstdint>

#include "craneassist/can/can_frame.hpp"

namespace craneassist::can {

enum class SendStatus {
  kOk,
  kQueueFull,  // the interface's transmit queue is full (ENOBUFS/EAGAIN): not sent, not waited
  kError,      // any other failure (interface down, ...)
};
const char* to_string(SendStatus status);

// Bus state reported by the controller through error frames (CAN_ERR_FLAG).
enum BusErrorFlags : std::uint32_t {
  kBusErrorNone = 0,
  kBusOff = 1u << 0,               // CAN_ERR_BUSOFF
  kErrorPassive = 1u << 1,         // CAN_ERR_CRTL with CAN_ERR_CRTL_{RX,TX}_PASSIVE
  kErrorWarning = 1u << 2,         // CAN_ERR_CRTL with CAN_ERR_CRTL_{RX,TX}_WARNING
  kBusErrorOther = 1u << 3,        // any other error class (protocol, ack, lost arbitration, ...)
  kControllerRestarted = 1u << 4,  // CAN_ERR_RESTARTED
};

enum class ReceiveKind {
  kNone,         // nothing waiting
  kFrame,        // a data frame in `frame`
  kBusError,     // an error frame; `bus_error` holds BusErrorFlags
  kUnsupported,  // a remote or otherwise unusable frame (counted, ignored)
  kError,        // the receive call failed
};

struct Received {
  ReceiveKind kind = ReceiveKind::kNone;
  CanFrame frame;
  TimestampUs timestamp_us = 0;  // kernel receive time, microseconds since the Unix epoch
  std::uint32_t bus_error = kBusErrorNone;
};

class Transport {
 public:
  virtual ~Transport() = default;
  // Queues one frame without waiting. Safe to call from two threads at once.
  virtual SendStatus send(const CanFrame& frame) = 0;
  // Takes the next waiting frame, if any, without waiting. One receiving thread.
  virtual void receive(Received& out) = 0;
  // Waits up to timeout_ms for something to receive (start-up and the emulator only).
  virtual bool wait_readable(int timeout_ms) = 0;
  virtual const char* interface_name() const = 0;
};

// Microseconds since the Unix epoch (CLOCK_REALTIME), the time base of received timestamps.
TimestampUs realtime_now_us();

}  // namespace craneassist::can
