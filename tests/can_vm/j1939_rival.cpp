// A second J1939 node that wants the same source address as craneassist, for the can_vm test
// (tests/can_vm/can_backend.sh). Written against the raw socket and J1939-81 directly, not the
// project's codecs, so that it checks them rather than agreeing with them.
//
//   j1939_rival IFACE ADDRESS_HEX NAME_HEX SECONDS
//
// It listens on IFACE for SECONDS. When another node claims ADDRESS (Address Claimed, PGN
// 0xEE00, 8 data bytes = the NAME, least significant byte first) it claims the address too, as a
// node that has just powered up. When the other node then claims again, the numerically lower
// NAME wins: with the lower NAME the rival repeats its claim; with the higher it sends Cannot
// Claim Address (from the null address 0xFE) and falls silent. Each step is printed.
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace {

std::uint32_t claim_id(std::uint8_t source) {
  // Priority 6, PGN 0xEE00 (PDU1), destination 0xFF (global).
  return (6u << 26) | (0xEEu << 16) | (0xFFu << 8) | source;
}

void send_claim(int fd, std::uint8_t source, std::uint64_t name, const char* what) {
  can_frame f{};
  f.can_id = claim_id(source) | CAN_EFF_FLAG;
  f.can_dlc = 8;
  for (int i = 0; i < 8; ++i) f.data[i] = static_cast<std::uint8_t>(name >> (8 * i));
  const bool ok = write(fd, &f, sizeof f) == static_cast<ssize_t>(sizeof f);
  std::printf("j1939_rival: %s: %08X#%016llX%s\n", what, claim_id(source),
              static_cast<unsigned long long>(name), ok ? "" : " (send failed)");
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: j1939_rival IFACE ADDRESS_HEX NAME_HEX SECONDS\n");
    return 2;
  }
  const auto address = static_cast<std::uint8_t>(std::strtoul(argv[2], nullptr, 16));
  const std::uint64_t name = std::strtoull(argv[3], nullptr, 16);
  const double seconds = std::strtod(argv[4], nullptr);
  const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) return 1;
  ifreq ifr{};
  std::snprintf(ifr.ifr_name, sizeof ifr.ifr_name, "%s", argv[1]);
  if (ioctl(fd, SIOCGIFINDEX, &ifr) < 0) return 1;
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) return 1;
  timeval tv{0, 50000};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::printf("j1939_rival: listening for claims of 0x%02X, NAME %016llX\n", address,
              static_cast<unsigned long long>(name));
  std::fflush(stdout);

  enum { kIdle, kContending, kHolding, kLost } state = kIdle;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    can_frame f{};
    if (read(fd, &f, sizeof f) != static_cast<ssize_t>(sizeof f)) continue;
    if ((f.can_id & CAN_EFF_FLAG) == 0 || (f.can_id & CAN_ERR_FLAG) != 0 || f.can_dlc != 8) {
      continue;
    }
    const std::uint32_t id = f.can_id & CAN_EFF_MASK;
    if (((id >> 16) & 0x3FFu) != 0xEEu || (id & 0xFFu) != address) continue;  // DP 0, PF 0xEE
    std::uint64_t theirs = 0;
    for (int i = 0; i < 8; ++i) theirs |= static_cast<std::uint64_t>(f.data[i]) << (8 * i);
    if (theirs == name) continue;
    std::printf("j1939_rival: 0x%02X claimed by NAME %016llX\n", address,
                static_cast<unsigned long long>(theirs));
    if (state == kIdle) {
      send_claim(fd, address, name, "contending claim");
      state = kContending;
    } else if (state != kLost && name < theirs) {
      send_claim(fd, address, name, "the rival has priority, claims again");
      state = kHolding;
    } else if (state != kLost) {
      send_claim(fd, 0xFE, name, "the rival gives way: Cannot Claim Address");
      state = kLost;
    }
  }
  close(fd);
  return 0;
}
