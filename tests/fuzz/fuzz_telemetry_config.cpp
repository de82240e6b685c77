// DDS telemetry settings files (config::parse_telemetry_config, docs/telemetry.md): any bytes
// are rejected with a ConfigError naming the source, or give settings with valid rates.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "craneassist/config/config_error.hpp"
#include "craneassist/config/telemetry_config.hpp"
#include "fuzz_check.hpp"

using craneassist::config::ConfigError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto cfg = craneassist::config::parse_telemetry_config(text, "fuzz.yaml", "/nonexistent");
    FUZZ_CHECK(cfg.source_name == "fuzz.yaml", "the settings name their source");
  } catch (const ConfigError& e) {
    FUZZ_CHECK(e.file() == "fuzz.yaml", "the error names the file");
  }
  return 0;
}
