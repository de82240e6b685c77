#include "craneassist/can/j1939.hpp"

namespace craneassist::can::j1939 {

const char* to_string(IdStatus status) {
  switch (status) {
    case IdStatus::kOk:
      return "ok";
    case IdStatus::kBadPriority:
      return "priority above 7";
    case IdStatus::kBadPgn:
      return "PGN above 18 bits or in the EDP=DP=1 page";
    case IdStatus::kPdu1LowByteSet:
      return "PDU1 PGN with a nonzero low byte";
  }
  return "unknown";
}

IdStatus make_id(std::uint8_t priority, std::uint32_t pgn_value, std::uint8_t source,
                 std::uint8_t destination_address, std::uint32_t& raw) {
  if (priority > 7) return IdStatus::kBadPriority;
  if (pgn_value > kMaxPgn || (pgn_value >> 16) == 0x3u) return IdStatus::kBadPgn;
  Identifier id;
  id.priority = priority;
  id.extended_data_page = ((pgn_value >> 17) & 1u) != 0;
  id.data_page = ((pgn_value >> 16) & 1u) != 0;
  id.pdu_format = static_cast<std::uint8_t>((pgn_value >> 8) & 0xFFu);
  if (is_pdu1(id.pdu_format)) {
    if ((pgn_value & 0xFFu) != 0) return IdStatus::kPdu1LowByteSet;
    id.pdu_specific = destination_address;
  } else {
    id.pdu_specific = static_cast<std::uint8_t>(pgn_value & 0xFFu);
  }
  id.source_address = source;
  raw = compose(id);
  return IdStatus::kOk;
}

}  // namespace craneassist::can::j1939
