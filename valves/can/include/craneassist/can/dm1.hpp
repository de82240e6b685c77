// SAE J1939-73 DM1, Active Diagnostic Trouble Codes: PGN 65226 (0xFECA), broadcast by a node
// once a second and on change (docs/can.md, "Valve supervision").
//
// Single-frame form (no or one active DTC), 8 bytes:
//   byte 1  lamp status, 2 bits each: bits 8-7 MIL, 6-5 red stop lamp, 4-3 amber warning lamp,
//           2-1 protect lamp (00 off, 01 on, 10 error, 11 not available)
//   byte 2  lamp flash, 2 bits each in the same order
//   bytes 3-6 the DTC: SPN 19 bits (byte 3 = bits 0-7, byte 4 = bits 8-15, byte 5 bits 8-6 =
//           bits 16-18), FMI byte 5 bits 5-1, occurrence count byte 6 bits 7-1, SPN conversion
//           method byte 6 bit 8
//   bytes 7-8 0xFF
// No active DTC is sent as SPN 0, FMI 0 (bytes 3-6 zero); some nodes send them as 0xFF.
//
// Two or more DTCs need more than 8 bytes: the node sends them with the transport protocol's
// broadcast (TP.CM BAM, PGN 60416 (0xEC00), then TP.DT packets, PGN 60160). The packets are not
// reassembled here; decode_dm1_announcement reads the BAM, which tells that such a DM1 is coming
// and its size: 2 + 4 bytes per DTC. A DM1 that needs the transport protocol therefore holds at
// least two active DTCs. TP.DT frames carry PGN 60160, so they are never misread as a DM1.
//
// Nothing here allocates or throws.
#pragma once

#include <cstdint>

#include "craneassist/can/can_frame.hpp"

namespace craneassist::can::j1939 {

inline constexpr std::uint32_t kPgnDm1 = 0xFECA;   // 65226
inline constexpr std::uint32_t kPgnTpCm = 0xEC00;  // 60416, transport protocol connection mgmt
inline constexpr std::uint32_t kPgnTpDt = 0xEB00;  // 60160, transport protocol data transfer
inline constexpr std::uint32_t kNoSpn = 0;
inline constexpr std::uint32_t kSpnNotAvailable = 0x7FFFF;  // all 19 bits set

enum class Lamp : std::uint8_t { kOff = 0, kOn = 1, kError = 2, kNotAvailable = 3 };

struct Dm1 {
  Lamp mil = Lamp::kOff;
  Lamp red_stop = Lamp::kOff;
  Lamp amber_warning = Lamp::kOff;
  Lamp protect = Lamp::kOff;
  std::uint8_t flash = 0xFF;          // byte 2 as sent
  std::uint32_t spn = kNoSpn;         // 19 bits
  std::uint8_t fmi = 0;               // 5 bits
  std::uint8_t occurrence_count = 0;  // 7 bits
  bool conversion_method = false;
};

enum class Dm1Status {
  kOk,
  kNotDm1,    // another PGN (or an 11-bit identifier)
  kTooShort,  // a DM1 with fewer than the 6 bytes that hold the lamps and the first DTC
};

// The DM1's sender in `source`. Bytes 7-8 are not read (they are 0xFF in the single-frame form).
Dm1Status decode_dm1(const CanFrame& frame, Dm1& dm1, std::uint8_t& source);
// For the emulator and tests: the single-frame DM1 from `source`, priority 6.
void encode_dm1(const Dm1& dm1, std::uint8_t source, CanFrame& frame);

// A DTC is active: an SPN other than 0 and "not available".
bool has_active_dtc(const Dm1& dm1);
// craneassist's stop rule for a DM1 (docs/can.md): the red stop lamp on, or any active DTC.
bool dm1_requires_stop(const Dm1& dm1);

// A TP.CM BAM announcing a multi-packet DM1 from `source`: its size in bytes (2 + 4 per DTC).
bool decode_dm1_announcement(const CanFrame& frame, std::uint8_t& source, std::uint16_t& size);

}  // namespace craneassist::can::j1939
