// CAN mapping files (can::parse_can_mapping, docs/can.md; config/can/*.yaml): any bytes are
// rejected with a ConfigError naming the source, or give a mapping whose every signal passes
// validate() and whose valve outputs encode a command.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "craneassist/can/mapping_config.hpp"
#include "craneassist/can/valve_frames.hpp"
#include "craneassist/config/config_error.hpp"
#include "fuzz_check.hpp"

namespace can = craneassist::can;
using craneassist::config::ConfigError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const can::CanMapping mapping = can::parse_can_mapping(text, "fuzz.yaml");
    for (const can::JointMapping& joint : mapping.joints) {
      FUZZ_CHECK(can::validate(joint.position) == can::SpecError::kNone, "a valid position");
      if (joint.pressure_a) {
        FUZZ_CHECK(can::validate(*joint.pressure_a) == can::SpecError::kNone, "a valid pressure");
      }
      if (joint.pressure_b) {
        FUZZ_CHECK(can::validate(*joint.pressure_b) == can::SpecError::kNone, "a valid pressure");
      }
      can::CanFrame frame;
      for (double spool : {-1.0, -0.5, 0.0, 0.25, 1.0}) {
        FUZZ_CHECK(can::encode_valve_command(joint.valve, spool, frame), "a usable valve output");
        FUZZ_CHECK(can::is_valid(frame) && can::is_valve_frame(joint.valve, frame),
                   "the command frame is the valve's");
      }
      FUZZ_CHECK(can::encode_valve_block(joint.valve, frame), "a block command");
    }
    if (mapping.pump.pressure) {
      FUZZ_CHECK(can::validate(*mapping.pump.pressure) == can::SpecError::kNone, "pump pressure");
    }
    if (mapping.pump.flow) {
      FUZZ_CHECK(can::validate(*mapping.pump.flow) == can::SpecError::kNone, "pump flow");
    }
  } catch (const ConfigError& e) {
    FUZZ_CHECK(e.file() == "fuzz.yaml", "the error names the file");
  }
  return 0;
}
