// SAE J1939-81 / ISO 11783-5 network management: the NAME, the Address Claimed, Cannot Claim
// Address and Request messages, and the claim procedure of a node with one fixed address
// (docs/can.md, "Address claim").
//
//   Address Claimed      PGN 60928 (0xEE00), priority 6, destination 0xFF, source = the claimed
//                        address, 8 data bytes = the NAME, least significant byte first
//   Cannot Claim Address the same PGN from the null address 0xFE, with the NAME
//   Request              PGN 59904 (0xEA00), 3 data bytes = the requested PGN, little endian
//                        (00 EE 00 asks every node, or the one addressed, for its claim)
//
// NAME (64 bits): bits 0-20 identity number, 21-31 manufacturer code, 32-34 ECU instance,
// 35-39 function instance, 40-47 function, 48 reserved, 49-55 vehicle system, 56-59 vehicle
// system instance, 60-62 industry group, 63 arbitrary address capable. Two nodes claiming one
// address: the numerically lower NAME has priority and keeps it.
//
// craneassist is not arbitrary-address capable: valves accept commands from a configured source
// address only, so moving to another address would not help. A node that loses its address
// sends Cannot Claim Address and nothing else from that address.
//
// Nothing here allocates, throws or blocks.
#pragma once

#include <cstdint>

#include "craneassist/can/can_frame.hpp"
#include "craneassist/can/j1939.hpp"

namespace craneassist::can::j1939 {

inline constexpr std::uint32_t kPgnAddressClaimed = 0xEE00;  // 60928
inline constexpr std::uint32_t kPgnRequest = 0xEA00;         // 59904
inline constexpr std::uint8_t kNetworkPriority = 6;
// J1939-81: a node waits this long after its Address Claimed for a contending claim.
inline constexpr double kClaimTimeoutS = 0.25;

struct Name {
  std::uint32_t identity_number = 0;         // 21 bits
  std::uint16_t manufacturer_code = 0;       // 11 bits
  std::uint8_t ecu_instance = 0;             // 3 bits
  std::uint8_t function_instance = 0;        // 5 bits
  std::uint8_t function = 0;                 // 8 bits
  std::uint8_t vehicle_system = 0;           // 7 bits
  std::uint8_t vehicle_system_instance = 0;  // 4 bits
  std::uint8_t industry_group = 0;           // 3 bits
  bool arbitrary_address_capable = false;
};

// Fields wider than their bits are masked.
std::uint64_t pack_name(const Name& name);
Name unpack_name(std::uint64_t value);

// Address Claimed from `source` (or Cannot Claim Address when source is kNullAddress).
void encode_address_claimed(std::uint64_t name, std::uint8_t source, CanFrame& frame);
// A Request for `pgn` from `source` to `destination` (kGlobalAddress: every node).
void encode_request(std::uint32_t pgn, std::uint8_t source, std::uint8_t destination,
                    CanFrame& frame);

// An Address Claimed (or Cannot Claim, source 0xFE) with its 8 bytes: the sender and its NAME.
bool decode_address_claimed(const CanFrame& frame, std::uint64_t& name, std::uint8_t& source);
// A Request (at least 3 data bytes): the requested PGN and the destination it was sent to.
bool decode_request(const CanFrame& frame, std::uint32_t& pgn, std::uint8_t& destination);

enum class ClaimState : std::uint8_t {
  kIdle,      // not started: nothing may be sent from the address
  kClaiming,  // Address Claimed sent, waiting the claim timeout for a contending claim
  kClaimed,   // the address is ours
  kLost,      // a node with priority holds it: nothing is sent from it
};
const char* to_string(ClaimState state);

// The claim procedure of one fixed address, driven by the caller's clock and received frames.
// The caller sends the frame an action names.
class AddressClaimer {
 public:
  enum class Action : std::uint8_t {
    kNone,
    kSend,  // send `out`: our claim (re-asserted or answering a request), or a delayed Cannot Claim
    kLost,  // send `out` (Cannot Claim Address): a node with priority claimed our address
  };

  AddressClaimer(std::uint8_t address, std::uint64_t name, double timeout_s = kClaimTimeoutS);

  // Starts (or restarts) claiming at now_us: `out` is our Address Claimed, to be sent now.
  void start(std::int64_t now_us, CanFrame& out);
  // A received frame: a contending claim of our address, or a Request for address claimed.
  Action on_frame(const CanFrame& frame, std::int64_t now_us, CanFrame& out);
  // Time passing: the claim completes after the timeout with no contention; a Cannot Claim
  // answer to a request falls due (after J1939-81's pseudo-random delay of 0..153 ms).
  Action poll(std::int64_t now_us, CanFrame& out);

  ClaimState state() const { return state_; }
  std::uint8_t address() const { return address_; }
  std::uint64_t name() const { return name_; }
  // The NAME of the node that took the address (valid in kLost).
  std::uint64_t rival_name() const { return rival_name_; }

 private:
  std::uint8_t address_;
  std::uint64_t name_;
  std::int64_t timeout_us_;
  std::int64_t claimed_at_us_ = 0;   // when our last claim went out (kClaiming)
  std::int64_t answer_due_us_ = -1;  // a pending Cannot Claim answer (kLost), -1: none
  std::uint64_t rival_name_ = 0;
  ClaimState state_ = ClaimState::kIdle;
};

}  // namespace craneassist::can::j1939
