// Joystick mapping files (config::parse_joystick_config, docs/joystick.md): any bytes are
// rejected with a ConfigError naming the source, or give a mapping the input side can use.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "craneassist/config/joystick_config.hpp"
#include "fuzz_check.hpp"

using craneassist::config::ConfigError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto cfg = craneassist::config::parse_joystick_config(text, "fuzz.yaml");
    FUZZ_CHECK(cfg.source_name == "fuzz.yaml", "the config names its source");
    FUZZ_CHECK(cfg.monitor.stale_timeout_s > 0.0 && cfg.monitor.max_speed_m_s > 0.0,
               "the input monitor's limits are positive");
  } catch (const ConfigError& e) {
    FUZZ_CHECK(e.file() == "fuzz.yaml", "the error names the file");
  }
  return 0;
}
