#include "craneassist/can/address_claim.hpp"

#include <cmath>

#include "craneassist/can/j1939.hpp"

namespace craneassist::can::j1939 {

std::uint64_t pack_name(const Name& n) {
  return (static_cast<std::uint64_t>(n.identity_number) & 0x1FFFFFu) |
         (static_cast<std::uint64_t>(n.manufacturer_code & 0x7FFu) << 21) |
         (static_cast<std::uint64_t>(n.ecu_instance & 0x7u) << 32) |
         (static_cast<std::uint64_t>(n.function_instance & 0x1Fu) << 35) |
         (static_cast<std::uint64_t>(n.function) << 40) |
         (static_cast<std::uint64_t>(n.vehicle_system & 0x7Fu) << 49) |
         (static_cast<std::uint64_t>(n.vehicle_system_instance & 0xFu) << 56) |
         (static_cast<std::uint64_t>(n.industry_group & 0x7u) << 60) |
         (static_cast<std::uint64_t>(n.arbitrary_address_capable) << 63);
}

Name unpack_name(std::uint64_t v) {
  Name n;
  n.identity_number = static_cast<std::uint32_t>(v & 0x1FFFFFu);
  n.manufacturer_code = static_cast<std::uint16_t>((v >> 21) & 0x7FFu);
  n.ecu_instance = static_cast<std::uint8_t>((v >> 32) & 0x7u);
  n.function_instance = static_cast<std::uint8_t>((v >> 35) & 0x1Fu);
  n.function = static_cast<std::uint8_t>((v >> 40) & 0xFFu);
  n.vehicle_system = static_cast<std::uint8_t>((v >> 49) & 0x7Fu);
  n.vehicle_system_instance = static_cast<std::uint8_t>((v >> 56) & 0xFu);
  n.industry_group = static_cast<std::uint8_t>((v >> 60) & 0x7u);
  n.arbitrary_address_capable = ((v >> 63) & 1u) != 0;
  return n;
}

void encode_address_claimed(std::uint64_t name, std::uint8_t source, CanFrame& frame) {
  frame = CanFrame{};
  make_id(kNetworkPriority, kPgnAddressClaimed, source, kGlobalAddress, frame.id);
  frame.extended = true;
  frame.dlc = 8;
  for (std::size_t i = 0; i < 8; ++i) frame.data[i] = static_cast<std::uint8_t>(name >> (8 * i));
}

void encode_request(std::uint32_t pgn_value, std::uint8_t source, std::uint8_t destination,
                    CanFrame& frame) {
  frame = CanFrame{};
  make_id(kNetworkPriority, kPgnRequest, source, destination, frame.id);
  frame.extended = true;
  frame.dlc = 3;
  frame.data[0] = static_cast<std::uint8_t>(pgn_value);
  frame.data[1] = static_cast<std::uint8_t>(pgn_value >> 8);
  frame.data[2] = static_cast<std::uint8_t>(pgn_value >> 16);
}

bool decode_address_claimed(const CanFrame& frame, std::uint64_t& name, std::uint8_t& source) {
  if (!frame.extended || frame.dlc != 8) return false;
  const Identifier id = decompose(frame.id);
  if (pgn(id) != kPgnAddressClaimed) return false;
  name = 0;
  for (std::size_t i = 0; i < 8; ++i) name |= static_cast<std::uint64_t>(frame.data[i]) << (8 * i);
  source = id.source_address;
  return true;
}

bool decode_request(const CanFrame& frame, std::uint32_t& requested, std::uint8_t& destination) {
  // J1939-21 sends 3 bytes; some nodes pad the frame to 8 with 0xFF.
  if (!frame.extended || frame.dlc < 3) return false;
  const Identifier id = decompose(frame.id);
  if (pgn(id) != kPgnRequest) return false;
  requested = static_cast<std::uint32_t>(frame.data[0]) |
              (static_cast<std::uint32_t>(frame.data[1]) << 8) |
              (static_cast<std::uint32_t>(frame.data[2]) << 16);
  destination = j1939::destination(id);
  return true;
}

const char* to_string(ClaimState state) {
  switch (state) {
    case ClaimState::kIdle:
      return "not claimed";
    case ClaimState::kClaiming:
      return "claiming";
    case ClaimState::kClaimed:
      return "claimed";
    case ClaimState::kLost:
      return "lost";
  }
  return "?";
}

AddressClaimer::AddressClaimer(std::uint8_t address, std::uint64_t name, double timeout_s)
    : address_(address),
      name_(name),
      timeout_us_(static_cast<std::int64_t>(std::llround(timeout_s * 1e6))) {}

void AddressClaimer::start(std::int64_t now_us, CanFrame& out) {
  state_ = ClaimState::kClaiming;
  claimed_at_us_ = now_us;
  answer_due_us_ = -1;
  rival_name_ = 0;
  encode_address_claimed(name_, address_, out);
}

AddressClaimer::Action AddressClaimer::on_frame(const CanFrame& frame, std::int64_t now_us,
                                                CanFrame& out) {
  std::uint64_t their_name = 0;
  std::uint8_t source = 0;
  const bool active = state_ == ClaimState::kClaiming || state_ == ClaimState::kClaimed;
  if (decode_address_claimed(frame, their_name, source)) {
    // Cannot Claim messages (source 0xFE) and claims of other addresses do not concern us.
    if (!active || source != address_) return Action::kNone;
    if (their_name > name_) {
      // We have priority: say so again; the other node must give way (Cannot Claim).
      if (state_ == ClaimState::kClaiming) claimed_at_us_ = now_us;
      encode_address_claimed(name_, address_, out);
      return Action::kSend;
    }
    // A lower NAME has priority. An equal NAME is a second node configured like this one: two
    // senders of the same valve commands, so this one gives way as well.
    state_ = ClaimState::kLost;
    rival_name_ = their_name;
    answer_due_us_ = -1;
    encode_address_claimed(name_, kNullAddress, out);
    return Action::kLost;
  }
  std::uint32_t requested = 0;
  std::uint8_t destination = 0;
  if (decode_request(frame, requested, destination) && requested == kPgnAddressClaimed) {
    if (active && (destination == kGlobalAddress || destination == address_)) {
      encode_address_claimed(name_, address_, out);
      return Action::kSend;
    }
    if (state_ == ClaimState::kLost && destination == kGlobalAddress && answer_due_us_ < 0) {
      // J1939-81: a node without an address answers after a pseudo-random 0..153 ms (0.6 ms
      // steps), so that several such answers, all from 0xFE, do not collide on the bus.
      std::uint64_t x = name_ ^ static_cast<std::uint64_t>(now_us);
      x ^= x >> 33;
      x *= 0xFF51AFD7ED558CCDull;
      x ^= x >> 33;
      answer_due_us_ = now_us + static_cast<std::int64_t>((x & 0xFFu) * 600u);
    }
  }
  return Action::kNone;
}

AddressClaimer::Action AddressClaimer::poll(std::int64_t now_us, CanFrame& out) {
  if (state_ == ClaimState::kClaiming && now_us - claimed_at_us_ >= timeout_us_) {
    state_ = ClaimState::kClaimed;
  }
  if (state_ == ClaimState::kLost && answer_due_us_ >= 0 && now_us >= answer_due_us_) {
    answer_due_us_ = -1;
    encode_address_claimed(name_, kNullAddress, out);
    return Action::kSend;
  }
  return Action::kNone;
}

}  // namespace craneassist::can::j1939
