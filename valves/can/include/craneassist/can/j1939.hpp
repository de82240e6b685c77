// SAE J1939-21 / ISO 11783-3 29-bit identifiers.
//
//   bits 28..26  priority (0 highest .. 7)
//   bit  25      extended data page (EDP)
//   bit  24      data page (DP)
//   bits 23..16  PDU format (PF)
//   bits 15..8   PDU specific (PS): destination address if PF < 240 (PDU1), group extension
//                if PF >= 240 (PDU2)
//   bits  7..0   source address (SA)
//
// PGN = EDP:DP:PF:PS as an 18-bit number, with PS taken as 0 for PDU1 (the destination is not
// part of the PGN). EDP = 1 with DP = 1 is the ISO 15765-3 page and not a J1939 PGN; compose and
// decompose carry it through, make_id rejects it.
#pragma once

#include <cstdint>

namespace craneassist::can::j1939 {

inline constexpr std::uint8_t kGlobalAddress = 0xFF;  // destination "all"
inline constexpr std::uint8_t kNullAddress = 0xFE;    // no address claimed
inline constexpr std::uint32_t kMaxPgn = 0x3FFFF;

struct Identifier {
  std::uint8_t priority = 6;  // 0..7
  bool extended_data_page = false;
  bool data_page = false;
  std::uint8_t pdu_format = 0;
  std::uint8_t pdu_specific = 0;
  std::uint8_t source_address = kNullAddress;
};

constexpr bool is_pdu1(std::uint8_t pdu_format) {
  return pdu_format < 240;
}

// The 29-bit identifier; priority is masked to 3 bits.
constexpr std::uint32_t compose(const Identifier& id) {
  return (static_cast<std::uint32_t>(id.priority & 0x7u) << 26) |
         (static_cast<std::uint32_t>(id.extended_data_page) << 25) |
         (static_cast<std::uint32_t>(id.data_page) << 24) |
         (static_cast<std::uint32_t>(id.pdu_format) << 16) |
         (static_cast<std::uint32_t>(id.pdu_specific) << 8) | id.source_address;
}

// The fields of a 29-bit identifier (bits above 28 are ignored).
constexpr Identifier decompose(std::uint32_t raw) {
  Identifier id;
  id.priority = static_cast<std::uint8_t>((raw >> 26) & 0x7u);
  id.extended_data_page = ((raw >> 25) & 1u) != 0;
  id.data_page = ((raw >> 24) & 1u) != 0;
  id.pdu_format = static_cast<std::uint8_t>((raw >> 16) & 0xFFu);
  id.pdu_specific = static_cast<std::uint8_t>((raw >> 8) & 0xFFu);
  id.source_address = static_cast<std::uint8_t>(raw & 0xFFu);
  return id;
}

constexpr std::uint32_t pgn(const Identifier& id) {
  const std::uint32_t ps = is_pdu1(id.pdu_format) ? 0u : id.pdu_specific;
  return (static_cast<std::uint32_t>(id.extended_data_page) << 17) |
         (static_cast<std::uint32_t>(id.data_page) << 16) |
         (static_cast<std::uint32_t>(id.pdu_format) << 8) | ps;
}

// Destination address: PS for PDU1, the global address for PDU2 (broadcast).
constexpr std::uint8_t destination(const Identifier& id) {
  return is_pdu1(id.pdu_format) ? id.pdu_specific : kGlobalAddress;
}

enum class IdStatus {
  kOk,
  kBadPriority,     // above 7
  kBadPgn,          // above 18 bits, or the EDP = DP = 1 page
  kPdu1LowByteSet,  // a PDU1 PGN must have 0 in its low byte (that byte is the destination)
};
const char* to_string(IdStatus status);

// Builds the identifier of a message: for PDU1 PGNs the destination goes into PS, for PDU2 PGNs
// the destination is ignored (the message is a broadcast). On failure raw is left unchanged.
IdStatus make_id(std::uint8_t priority, std::uint32_t pgn_value, std::uint8_t source,
                 std::uint8_t destination_address, std::uint32_t& raw);

}  // namespace craneassist::can::j1939
