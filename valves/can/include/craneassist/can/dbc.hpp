// DBC files (the CAN database format of Vector's CANdb++, read by canmatrix, cantools, SavvyCAN,
// PCAN-Explorer and most bus tools): the subset a valve group and its sensors need.
//
// Read: messages (BO_), their signals (SG_), the message cycle time (BA_ "GenMsgCycleTime") and
// the frame format (BA_ "VFrameFormat"). Everything else (comments, value tables, other
// attributes, node lists, environment variables) is skipped, statement by statement, so a
// machine maker's full DBC loads. Multiplexed signals are read and marked; the mapping refuses
// them. An identifier with bit 31 set is a 29-bit identifier (DBC's convention), as is any
// identifier above 0x7FF.
//
// Write: the DBC of a mapping file, with every frame craneassist sends (valve commands, the
// heartbeat) and receives (positions, pressures, the pump), scalings and units as the mapping file
// states them, cycle times, and the J1939 attributes for ISO 11783 messages (VFrameFormat
// J1939PG, ProtocolType J1939, the sender's NmStationAddress). Names: messages and signals by
// joint and role (`lift_position`, `slew_pressure_a`, `AuxValveCommand1`), see docs/can.md.
//
// Parsing is outside the control loop: it allocates and throws config::ConfigError naming the
// file, line and statement ("machine.dbc:12: field 'BO_ 2364539904': ...").
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "craneassist/can/mapping_config.hpp"
#include "craneassist/can/signal_map.hpp"

namespace craneassist::can {

struct DbcSignal {
  std::string name;
  // Scale, offset, minimum and maximum in the DBC's unit (spec.unit), not converted to SI.
  SignalSpec spec;
  bool multiplexed = false;  // a multiplexor or multiplexed signal (M, mN): not supported
  int value_type = 0;        // SIG_VALTYPE_: 0 integer, 1 IEEE float, 2 double (not supported)
  int line = 0;
};

struct DbcMessage {
  std::string name;
  std::uint32_t id = 0;  // without DBC's bit 31
  bool extended = false;
  std::uint8_t dlc = 8;
  std::string sender;
  std::optional<double> cycle_s;  // GenMsgCycleTime, when set and nonzero
  bool j1939 = false;             // VFrameFormat J1939PG
  std::vector<DbcSignal> signals;
  int line = 0;
};

struct Dbc {
  std::string source;  // the file name, for messages
  std::vector<DbcMessage> messages;

  const DbcMessage* message(std::string_view name) const;
};

// Throws config::ConfigError for a statement it cannot read.
Dbc parse_dbc(std::string_view text, std::string_view source_name);
// Reads the file (at most 4 MiB); throws config::ConfigError naming it when it cannot be read.
Dbc load_dbc(const std::filesystem::path& path);

// The DBC of a mapping. `title` goes into the VERSION line and a comment (the mapping's file).
std::string write_dbc(const CanMapping& mapping, std::string_view title);

}  // namespace craneassist::can
