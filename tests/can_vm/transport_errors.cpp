// The project's SocketCAN transport (SocketCanTransport) on a real kernel: runs in the CAN test VM
// (tests/can_vm/can_backend.sh), where vcan0 is up. Controller error frames are written to the
// bus through a raw socket, as a CAN driver reports them (can_id with CAN_ERR_FLAG and the error
// class, details in the payload; linux/can/error.h), and the transport must classify each one.
// vcan has no controller of its own, so this is the way to put them on a real kernel bus.
#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

#include "craneassist/can/socketcan.hpp"

namespace {

using namespace craneassist::can;

std::string bus() {
  const char* v = std::getenv("CAN_VM_IFACE");
  return v != nullptr && *v != '\0' ? v : "vcan0";
}

// A plain raw socket that writes what a controller driver would deliver.
class Injector {
 public:
  Injector() {
    fd_ = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
    EXPECT_GE(fd_, 0) << std::strerror(errno);
    ifreq ifr{};
    std::strncpy(ifr.ifr_name, bus().c_str(), IFNAMSIZ - 1);
    EXPECT_EQ(::ioctl(fd_, SIOCGIFINDEX, &ifr), 0) << std::strerror(errno);
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifr.ifr_ifindex;
    EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0)
        << std::strerror(errno);
  }
  Injector(const Injector&) = delete;
  Injector& operator=(const Injector&) = delete;
  ~Injector() { ::close(fd_); }

  void error_frame(canid_t error_class, std::uint8_t d1 = 0, std::uint8_t d2 = 0) {
    can_frame f{};
    f.can_id = CAN_ERR_FLAG | error_class;
    f.len = CAN_ERR_DLC;
    f.data[1] = d1;
    f.data[2] = d2;
    ASSERT_EQ(::write(fd_, &f, sizeof f), static_cast<ssize_t>(sizeof f)) << std::strerror(errno);
  }
  void data_frame(canid_t id) {
    can_frame f{};
    f.can_id = id;
    f.len = 1;
    f.data[0] = 0x5A;
    ASSERT_EQ(::write(fd_, &f, sizeof f), static_cast<ssize_t>(sizeof f)) << std::strerror(errno);
  }

 private:
  int fd_ = -1;
};

Received next(SocketCanTransport& t) {
  Received r;
  if (t.wait_readable(1000)) t.receive(r);
  return r;
}

struct ErrorCase {
  const char* what;
  canid_t error_class;
  std::uint8_t d1;
  std::uint8_t d2;
  std::uint32_t expected;
};

TEST(SocketCanTransport, ClassifiesEveryControllerErrorFrameItSubscribes) {
  const ErrorCase cases[] = {
      {"bus-off", CAN_ERR_BUSOFF, 0, 0, kBusOff},
      {"error-passive (tx)", CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE, 0, kErrorPassive},
      {"error-passive (rx)", CAN_ERR_CRTL, CAN_ERR_CRTL_RX_PASSIVE, 0, kErrorPassive},
      {"error warning", CAN_ERR_CRTL, CAN_ERR_CRTL_TX_WARNING, 0, kErrorWarning},
      {"controller restarted", CAN_ERR_RESTARTED, 0, 0, kControllerRestarted},
      {"no ACK", CAN_ERR_ACK, 0, 0, kBusErrorOther},
      {"protocol (bit stuffing)", CAN_ERR_PROT, 0, CAN_ERR_PROT_STUFF, kBusErrorOther},
      {"bus error", CAN_ERR_BUSERROR, 0, 0, kBusErrorOther},
      {"bus-off after ACK errors", CAN_ERR_BUSOFF | CAN_ERR_ACK, 0, 0, kBusOff | kBusErrorOther},
  };
  SocketCanTransport transport(bus());
  Injector inject;
  for (const auto& c : cases) {
    inject.error_frame(c.error_class, c.d1, c.d2);
    const Received r = next(transport);
    ASSERT_EQ(r.kind, ReceiveKind::kBusError) << c.what << ": not received as an error frame";
    EXPECT_EQ(r.bus_error, c.expected) << c.what;
    EXPECT_GT(r.timestamp_us, 0) << c.what;
  }
}

TEST(SocketCanTransport, ErrorClassesItDoesNotSubscribeAreFilteredByTheKernel) {
  SocketCanTransport transport(bus());
  Injector inject;
  // Lost arbitration, transceiver status and TX timeout are not in the transport's error mask:
  // the kernel does not deliver them; the data frame after them arrives first.
  inject.error_frame(CAN_ERR_LOSTARB);
  inject.error_frame(CAN_ERR_TRX);
  inject.error_frame(CAN_ERR_TX_TIMEOUT);
  inject.data_frame(0x123);
  const Received r = next(transport);
  ASSERT_EQ(r.kind, ReceiveKind::kFrame);
  EXPECT_EQ(r.frame.id, 0x123u);
  EXPECT_FALSE(r.frame.extended);
  Received none;
  transport.receive(none);
  EXPECT_EQ(none.kind, ReceiveKind::kNone);
}

}  // namespace
