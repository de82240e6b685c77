// DBC files (can::parse_dbc, docs/can.md#dbc-files; a mapping's `dbc:` and machine makers'
// databases): any bytes are rejected with a ConfigError naming the source, or give messages whose
// identifiers fit their format and whose integer signals pass validate().
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "craneassist/can/dbc.hpp"
#include "craneassist/config/config_error.hpp"
#include "fuzz_check.hpp"

namespace can = craneassist::can;
using craneassist::config::ConfigError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const can::Dbc dbc = can::parse_dbc(text, "fuzz.dbc");
    for (const can::DbcMessage& m : dbc.messages) {
      FUZZ_CHECK(m.id <= (m.extended ? can::kMaxExtendedId : can::kMaxStandardId),
                 "the identifier fits its format");
      FUZZ_CHECK(m.dlc <= 8, "a classic CAN length");
      FUZZ_CHECK(!m.cycle_s || *m.cycle_s > 0.0, "a positive cycle time");
      for (const can::DbcSignal& s : m.signals) {
        FUZZ_CHECK(can::validate(s.spec) == can::SpecError::kNone, "a valid signal");
        FUZZ_CHECK(dbc.message(m.name) != nullptr, "found by name");
      }
    }
  } catch (const ConfigError& e) {
    FUZZ_CHECK(e.file() == "fuzz.dbc", "the error names the file");
  }
  return 0;
}
