#include "craneassist/can/dm1.hpp"

#include "craneassist/can/address_claim.hpp"
#include "craneassist/can/j1939.hpp"

namespace craneassist::can::j1939 {

namespace {
constexpr std::uint8_t kTpCmBam = 32;  // TP.CM control byte: broadcast announce
}  // namespace

Dm1Status decode_dm1(const CanFrame& frame, Dm1& dm1, std::uint8_t& source) {
  if (!frame.extended) return Dm1Status::kNotDm1;
  const Identifier id = decompose(frame.id);
  if (pgn(id) != kPgnDm1) return Dm1Status::kNotDm1;
  source = id.source_address;
  if (frame.dlc < 6) return Dm1Status::kTooShort;
  const std::uint8_t lamps = frame.data[0];
  dm1.mil = static_cast<Lamp>((lamps >> 6) & 0x3u);
  dm1.red_stop = static_cast<Lamp>((lamps >> 4) & 0x3u);
  dm1.amber_warning = static_cast<Lamp>((lamps >> 2) & 0x3u);
  dm1.protect = static_cast<Lamp>(lamps & 0x3u);
  dm1.flash = frame.data[1];
  dm1.spn = static_cast<std::uint32_t>(frame.data[2]) |
            (static_cast<std::uint32_t>(frame.data[3]) << 8) |
            (static_cast<std::uint32_t>((frame.data[4] >> 5) & 0x7u) << 16);
  dm1.fmi = frame.data[4] & 0x1Fu;
  dm1.occurrence_count = frame.data[5] & 0x7Fu;
  dm1.conversion_method = (frame.data[5] & 0x80u) != 0;
  return Dm1Status::kOk;
}

void encode_dm1(const Dm1& dm1, std::uint8_t source, CanFrame& frame) {
  frame = CanFrame{};
  make_id(kNetworkPriority, kPgnDm1, source, kGlobalAddress, frame.id);
  frame.extended = true;
  frame.dlc = 8;
  frame.data[0] = static_cast<std::uint8_t>(
      (static_cast<unsigned>(dm1.mil) << 6) | (static_cast<unsigned>(dm1.red_stop) << 4) |
      (static_cast<unsigned>(dm1.amber_warning) << 2) | static_cast<unsigned>(dm1.protect));
  frame.data[1] = dm1.flash;
  frame.data[2] = static_cast<std::uint8_t>(dm1.spn);
  frame.data[3] = static_cast<std::uint8_t>(dm1.spn >> 8);
  frame.data[4] = static_cast<std::uint8_t>((((dm1.spn >> 16) & 0x7u) << 5) | (dm1.fmi & 0x1Fu));
  frame.data[5] = static_cast<std::uint8_t>((dm1.conversion_method ? 0x80u : 0u) |
                                            (dm1.occurrence_count & 0x7Fu));
  frame.data[6] = 0xFF;
  frame.data[7] = 0xFF;
}

bool has_active_dtc(const Dm1& dm1) {
  return dm1.spn != kNoSpn && dm1.spn != kSpnNotAvailable;
}

bool dm1_requires_stop(const Dm1& dm1) {
  return dm1.red_stop == Lamp::kOn || has_active_dtc(dm1);
}

bool decode_dm1_announcement(const CanFrame& frame, std::uint8_t& source, std::uint16_t& size) {
  if (!frame.extended || frame.dlc != 8) return false;
  const Identifier id = decompose(frame.id);
  if (pgn(id) != kPgnTpCm || frame.data[0] != kTpCmBam) return false;
  const std::uint32_t announced = static_cast<std::uint32_t>(frame.data[5]) |
                                  (static_cast<std::uint32_t>(frame.data[6]) << 8) |
                                  (static_cast<std::uint32_t>(frame.data[7]) << 16);
  if (announced != kPgnDm1) return false;
  source = id.source_address;
  size = static_cast<std::uint16_t>(frame.data[1] | (frame.data[2] << 8));
  return true;
}

}  // namespace craneassist::can::j1939
