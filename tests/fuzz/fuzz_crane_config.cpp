// Crane configuration files (config::parse_crane_config, docs/config.md; the text behind
// load_crane_config): any bytes are rejected with a ConfigError naming the source, or give a
// validated crane model that the rest of the program can use (the resolution names, the
// energy-optimal choice, the payload).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "craneassist/config/crane_config.hpp"
#include "fuzz_check.hpp"

using craneassist::config::ConfigError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    craneassist::config::CraneConfig cfg =
        craneassist::config::parse_crane_config(text, "fuzz.yaml");
    FUZZ_CHECK(cfg.source_name == "fuzz.yaml", "the config names its source");
    craneassist::config::apply_energy_optimal(cfg);
    (void)craneassist::config::resolution_description(cfg);
    craneassist::config::set_payload_mass(cfg.model, 650.0);
  } catch (const ConfigError& e) {
    FUZZ_CHECK(e.file() == "fuzz.yaml", "the error names the file");
    FUZZ_CHECK(e.line() >= 0, "a line number");
  }
  return 0;
}
