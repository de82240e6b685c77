// A joint's valve command as a frame, per the mapping: the normalised spool command -1 (full
// retract) .. 0 (neutral) .. +1 (full extend) to and from its CAN frame. Used by the backend
// (encode) and the machine emulator (decode). Neither allocates nor throws.
//
// ISO 11783-7 Auxiliary Valve Command: spool > 0 -> extend at port flow spool, spool < 0 ->
// retract at port flow -spool, spool == 0 (or |spool| below 1e-6) -> block at flow 0.
// Signal output (a signed current or ratio): value = spool * full scale, where the full scale is
// the larger magnitude of the signal's min and max (1 when neither is given).
#pragma once

#include "craneassist/can/mapping_config.hpp"

namespace craneassist::can {

// The value a spool command of 1 stands for on a signal output.
double valve_full_scale(const SignalSpec& signal);

// Writes the frame (identifier, dlc, data) of the command. A non-finite spool is sent as block.
// Returns false only for an unusable mapping entry.
bool encode_valve_command(const ValveOutput& valve, double spool, CanFrame& frame);

// The block/neutral command of the valve (fail-safe: spool 0, state block).
bool encode_valve_block(const ValveOutput& valve, CanFrame& frame);

// True when the frame carries this valve's command (identifier, and for ISO 11783 the valve
// number and source address).
bool is_valve_frame(const ValveOutput& valve, const CanFrame& frame);

// Decodes a frame for which is_valve_frame holds. Returns false (spool untouched) when the frame
// is malformed (wrong dlc, a field out of range). `block`: the command is block/neutral (float
// is reported as spool 0 without block).
bool decode_valve_command(const ValveOutput& valve, const CanFrame& frame, double& spool,
                          bool& block);

}  // namespace craneassist::can
