// ISO 11783-7 auxiliary valve messages (tractor/implement hydraulics), as J1939 PDU2 broadcasts.
//
// Sources. The ISO standard itself was not available; the layouts follow the ISO 11783 SPN/PGN
// database published at isobus.net (pages for PGN 65072..65087 "Auxiliary valve N command", SPNs
// 1907/1908/1909/7872/7856 and their per-valve equivalents; PGN 65057/65065 "Auxiliary valve N
// measured flow", SPNs 2263/2264/2268/2269/2270/5178; SPNs 1985/14307 estimated flow, 5181 the
// estimated flow limit status), cross-checked against Open-SAE-J1939 (DanielMartensson,
// Src/ISO_11783/ISO_11783-7_Application_Layer/Auxiliary_Valve_Command.c and
// Auxiliary_Valve_Estimated_Flow.c). That library implements the older command layout: byte 1
// flow, byte 3 state/fail-safe exactly as below, priority 3, but byte 2 and bytes 4-8 all
// reserved (0xFF). The resolution mode (2.1) and the extended-resolution flow (bytes 4-5) are
// database additions of 2015/2018; a valve of the older layout should ignore them (they were
// reserved). extended_resolution = false leaves bytes 4-8 at 0xFF and sends resolution mode 00;
// the older frame differs from that only in byte 2 bits 1-2 (11 there).
//
// Auxiliary Valve Command, PGN 65072 + n (0xFE30 + n), n = valve 0..15, 8 bytes, priority 3,
// "100 ms when active" (the database's transmission rate; craneassist sends faster):
//   byte 1       port flow command, 0.4 %/bit, 0..250 = 0..100 %
//   byte 2 b1-2  resolution mode: 00 standard only, 01 extended and standard valid, 11 don't care
//   byte 2 b3-8  reserved, sent as 1
//   byte 3 b1-4  valve state: 0 block, 1 extend, 2 retract, 3 float, 15 don't care
//   byte 3 b5-6  reserved, sent as 1
//   byte 3 b7-8  fail-safe mode: 00 block, 01 float, 11 don't care
//   bytes 4-5    port flow, extended resolution, 0.0015625 %/bit (64000 = 100 %), little endian;
//                0xFFFF (not available) when the resolution mode is 00
//   bytes 6-8    reserved, 0xFF
//
// Auxiliary Valve Measured Flow, PGN 65056 + n (0xFE20 + n), 8 bytes, 100 ms:
//   byte 1       extend port measured flow, 1 %/bit, offset -125 %
//   byte 2       retract port measured flow, 1 %/bit, offset -125 %
//   bytes 3-4    extend port pressure, 5 kPa/bit
//   bytes 5-6    retract port pressure, 5 kPa/bit
//   byte 7       return port pressure, 16 kPa/bit
//   byte 8 b6-8  measured flow limit status (byte 8 bits 1-5 reserved)
// Note: the project brief named 65056 + n "measured position"; the database names it measured
// flow (with the port pressures), which is the message the issue asks to decode.
//
// Auxiliary Valve Estimated Flow, PGN 65040 + n (0xFE10 + n), 8 bytes:
//   byte 1, 2    extend / retract port estimated flow, 1 %/bit, offset -125 % (SPN database)
//   byte 3       b1-4 valve state, b5-6 reserved, b7-8 fail-safe mode    (Open-SAE-J1939 only)
//   byte 4 b6-8  estimated flow limit status                              (Open-SAE-J1939 only)
// NOT confirmed and therefore not decoded: the byte positions of the estimated-flow exit/reason
// code and of the 16-bit high-resolution estimated flow (SPN 9740 etc., 0.004 %/bit, -125 %).
//
// Not implemented: "measured position". Open-SAE-J1939 places an auxiliary valve measured
// position at PGN 0xFF20 + n (65312 + n), which lies in the proprietary-B range; no database
// entry confirmed it.
//
// Parameter ranges follow J1939-71: one-byte values 0..250 are valid, 0xFE is an error
// indicator, 0xFF not available; two-byte values 0..0xFAFF valid, 0xFExx error, 0xFFxx not
// available. Decoded fields outside the valid range come out as NaN (never an exception).
//
// Units inside craneassist: flows as fractions of the valve's full flow (1.0 = 100 %),
// pressures in Pa. Encode and decode neither allocate nor throw.
#pragma once

#include <cstdint>

#include "craneassist/can/can_frame.hpp"

namespace craneassist::can::iso11783 {

inline constexpr std::uint32_t kPgnAuxValveEstimatedFlow0 = 65040;  // 0xFE10
inline constexpr std::uint32_t kPgnAuxValveMeasuredFlow0 = 65056;   // 0xFE20
inline constexpr std::uint32_t kPgnAuxValveCommand0 = 65072;        // 0xFE30
inline constexpr std::uint8_t kAuxValveCount = 16;
inline constexpr std::uint8_t kDefaultPriority = 3;

inline constexpr double kStandardFlowPerBit = 0.004;      // 0.4 %/bit as a fraction
inline constexpr double kExtendedFlowPerBit = 1.5625e-5;  // 0.0015625 %/bit as a fraction

enum class ValveState : std::uint8_t {
  kBlock = 0,
  kExtend = 1,
  kRetract = 2,
  kFloat = 3,
  kError = 14,         // measured messages only: error indication
  kNotAvailable = 15,  // command: don't care; measured: not available
};

enum class FailSafeMode : std::uint8_t { kBlock = 0, kFloat = 1, kReserved = 2, kDontCare = 3 };

enum class LimitStatus : std::uint8_t {
  kNotLimited = 0,
  kOperatorLimited = 1,
  kLimitedHigh = 2,
  kLimitedLow = 3,
  kNonRecoverableFault = 6,
  kNotAvailable = 7,
};

const char* to_string(ValveState state);
const char* to_string(FailSafeMode mode);

enum class CodecStatus {
  kOk,
  kClamped,          // encode: a value outside its range was clamped; the frame was written
  kInvalidArgument,  // encode: non-finite value, valve above 15, priority above 7, reserved enum
  kWrongIdentifier,  // decode: not a 29-bit identifier of this message
  kBadLength,        // decode: dlc is not 8
  kBadField,         // decode: a field holds an error/not-available/reserved code (see below)
};
const char* to_string(CodecStatus status);

struct AuxValveCommand {
  std::uint8_t valve = 0;  // n, 0..15
  double flow = 0.0;       // port flow, fraction of full flow, 0..1
  ValveState state = ValveState::kBlock;
  FailSafeMode fail_safe = FailSafeMode::kBlock;
  bool extended_resolution = true;  // send the 16-bit field as well (resolution mode 01)
};

// Rounding: to nearest (half away from zero) for both fields, each from the commanded flow
// (the 8-bit field is not derived from the rounded 16-bit one). Flow outside [0, 1] is clamped
// and reported as kClamped. A non-finite flow or an enum outside the command's values (state
// kError, fail-safe kReserved) writes nothing and returns kInvalidArgument.
CodecStatus encode(const AuxValveCommand& command, std::uint8_t source_address,
                   std::uint8_t priority, CanFrame& frame);

// Decodes a command frame of any valve. The flow comes from the 16-bit field when the resolution
// mode says it is valid and it holds 0..0xFAFF, else from the 8-bit field. kBadField: the flow
// field used is above 100 % (the 8-bit one above 250, the 16-bit one above 64000; flow is NaN),
// or the state is a reserved code; the other fields are still filled. source_address receives
// the sender.
CodecStatus decode(const CanFrame& frame, AuxValveCommand& command, std::uint8_t& source_address);

struct AuxValveMeasuredFlow {
  std::uint8_t valve = 0;
  double extend_flow = 0.0;  // fraction, -1.25..1.25; negative: flow returning through the port
  double retract_flow = 0.0;
  double extend_pressure_pa = 0.0;
  double retract_pressure_pa = 0.0;
  double return_pressure_pa = 0.0;
  LimitStatus limit = LimitStatus::kNotAvailable;
};

// Encode (for the emulator and tests): NaN fields are sent as not available; finite values
// outside the field's range are clamped (kClamped).
CodecStatus encode(const AuxValveMeasuredFlow& message, std::uint8_t source_address,
                   std::uint8_t priority, CanFrame& frame);
// Decode: fields holding error / not-available codes come out as NaN (status kOk: a valve may
// legitimately not measure every port).
CodecStatus decode(const CanFrame& frame, AuxValveMeasuredFlow& message,
                   std::uint8_t& source_address);

struct AuxValveEstimatedFlow {
  std::uint8_t valve = 0;
  double extend_flow = 0.0;  // fraction, -1.25..1.25
  double retract_flow = 0.0;
  ValveState state = ValveState::kNotAvailable;
  FailSafeMode fail_safe = FailSafeMode::kDontCare;
  LimitStatus limit = LimitStatus::kNotAvailable;
};

CodecStatus encode(const AuxValveEstimatedFlow& message, std::uint8_t source_address,
                   std::uint8_t priority, CanFrame& frame);
CodecStatus decode(const CanFrame& frame, AuxValveEstimatedFlow& message,
                   std::uint8_t& source_address);

}  // namespace craneassist::can::iso11783
