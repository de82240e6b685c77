// The CAN mapping file: per crane joint, where its valve command goes and where its sensor
// feedback comes from (docs/can.md). Loaded once at start-up, outside the control loop; errors
// are config::ConfigError naming file, line and field, like the crane config.
//
//   format: craneassist-can-map/1
//   joints:
//     - name: slew
//       valve:
//         iso11783_avc: {valve: 0, source_address: 0x80, cycle: 20 ms}
//       position: {id: 0x18FF1021, extended: true, start_bit: 0, length: 16,
//                  byte_order: intel, signed: true, scale: 0.01, offset: 0, unit: deg}
//       pressure_a: {id: 0x18FF2021, extended: true, start_bit: 0, length: 16,
//                    byte_order: intel, scale: 0.01, unit: bar}
//
// A signal's scale, offset, min and max are in its `unit`; the loader converts them so the
// decoded value is SI (rad or m for positions, Pa for pressures, A for currents, a fraction
// for `%` or no unit).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "craneassist/can/iso11783_valve.hpp"
#include "craneassist/can/signal_map.hpp"
#include "craneassist/dynamics/model.hpp"

namespace craneassist::can {

inline constexpr const char* kMappingFormat = "craneassist-can-map/1";

// ISO 11783-7 Auxiliary Valve Command output (PGN 65072 + valve).
struct AvcOutput {
  std::uint8_t valve = 0;              // 0..15
  std::uint8_t source_address = 0x80;  // craneassist's address on the bus, 0..253
  std::uint8_t priority = iso11783::kDefaultPriority;
  double cycle_s = 0.02;  // send period, 1..100 ms
  iso11783::FailSafeMode fail_safe = iso11783::FailSafeMode::kBlock;
  bool extended_resolution = true;
};

// A current (or duty) command through a generic signal: signed, negative = retract.
struct SignalOutput {
  SignalSpec signal;  // decoded/encoded in A (unit A or mA) or as a fraction (unit % or none)
  double cycle_s = 0.02;
};

enum class ValveOutputKind { kIso11783Avc, kSignal };

struct ValveOutput {
  ValveOutputKind kind = ValveOutputKind::kIso11783Avc;
  AvcOutput avc;        // when kind == kIso11783Avc
  SignalOutput signal;  // when kind == kSignal
};

enum class PositionKind { kAngle, kLength };  // from the position signal's unit

// What a joint's valve reports back (`valve.reply`), supervised by the backend (docs/can.md,
// "Valve supervision"): the reply must keep coming (timeout) and must not report a fault.
struct ValveReply {
  // ISO 11783-7 valves: Auxiliary Valve Estimated Flow (PGN 65040 + the command's valve number)
  // from the valve's own source address.
  std::uint8_t source_address = 0;
  // Signal valves: the driver's status field, read raw (no scale), and the raw values that mean
  // OK; any other value is a fault.
  SignalSpec status;
  std::vector<std::uint64_t> ok_values;
  double timeout_s = 0.3;  // no reply for this long (or none this long after enable) -> fault
};

struct JointMapping {
  std::string name;
  ValveOutput valve;
  SignalSpec position;  // rad or m
  PositionKind position_kind = PositionKind::kAngle;
  std::optional<SignalSpec> pressure_a;  // Pa, piston side
  std::optional<SignalSpec> pressure_b;  // Pa, rod side
  std::optional<ValveReply> reply;       // optional supervision of the valve
  // Where the entry is in its file, for check_mapping_fits's errors (1-based; 0: built in code).
  int name_line = 0;
  int valve_line = 0;
  int position_line = 0;
};

// craneassist's own alive message (docs/can.md, "Heartbeat"): sent by the control loop at
// `cycle`; the machine side blocks every section when it has not seen the counter advance for
// `timeout`. A frozen loop stops it, while the watchdog's block commands keep flowing.
struct HeartbeatSpec {
  std::uint32_t id = 0;
  bool extended = true;
  double cycle_s = 0.02;   // send period
  double timeout_s = 0.1;  // the receiver's supervision time
};

// Pump measurements on the bus (optional; for the log and telemetry, the controller does not
// use them): supply pressure and delivered flow.
struct PumpMapping {
  std::optional<SignalSpec> pressure;  // Pa
  std::optional<SignalSpec> flow;      // m^3/s (unit L/min, m^3/s, ...)
};

// The grapple's swing sensor on the bus (optional; docs/can.md, "Swing sensor"): a two-axis
// inclination of the hanger from the vertical, towards the reach (radial) and across it
// (tangential, towards a positive slew), as MachineState::swing_* has it. The controller tunes its
// sway damping to the swing it measures (docs/sway.md); a machine without it is damped on the
// model alone.
struct GrappleMapping {
  std::optional<SignalSpec> swing_radial;      // rad
  std::optional<SignalSpec> swing_tangential;  // rad
};

// J1939-81 address claim of craneassist's source address before it sends anything from it
// (docs/can.md, "Address claim"). Every AVC command and a J1939 (29-bit) heartbeat are sent from
// `address`.
struct AddressClaimSpec {
  std::uint8_t address = 0x80;
  std::uint64_t name = 0;   // the J1939 NAME (address_claim.hpp), not arbitrary-address capable
  double timeout_s = 0.25;  // J1939-81: wait 250 ms for a contending claim
};

// J1939-73 DM1 (active diagnostic trouble codes) supervision of the listed nodes.
struct Dm1Supervision {
  std::vector<std::uint8_t> source_addresses;
};

struct CanMapping {
  std::string source;   // the file name, for messages
  int joints_line = 0;  // the line of `joints:` (0: built in code)
  std::vector<JointMapping> joints;
  std::optional<HeartbeatSpec> heartbeat;
  PumpMapping pump;
  GrappleMapping grapple;
  std::optional<AddressClaimSpec> address_claim;
  std::optional<Dm1Supervision> dm1;  // `diagnostics: {dm1: ...}`
};

// Throws config::ConfigError (file:line: field 'joints[1].position.length': reason).
CanMapping parse_can_mapping(std::string_view yaml_text, std::string_view source_name);
CanMapping load_can_mapping(const std::filesystem::path& path);

// Whether the mapping fits the crane: the same joints in the same order (as many, the same
// names), each position signal measuring what its joint is (an angle for a revolute joint, a
// length for a prismatic one) over the joint's whole range (a valid position outside the signal's
// min/max would be read as a malformed frame), each valve command encodable. Throws
// config::ConfigError naming the mapping file, line and field ("k70m_can.yaml:12: field
// 'joints[1].position': joint 'lift': the position signal's min/max do not cover the joint range
// ..."). The command line checks this before it opens a bus; CanBackend's constructor again.
void check_mapping_fits(const CanMapping& mapping, const dynamics::CraneModel& model);

}  // namespace craneassist::can
