// Scenario suite manifests (offline::parse_suite, docs/suite-format.md), read against the
// examples' folder so that the shipped replays resolve: any bytes are rejected with a ConfigError
// naming the manifest, or give runs whose replay files exist, and whose poses either fit the
// reference crane or are rejected by check_suite naming the manifest. The same bytes as a machine
// variants file (offline::parse_variants): rejected naming it, or variants whose valve fields
// lie in their ranges.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>

#include "craneassist/config/config_error.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/offline/scenario_suite.hpp"
#include "fuzz_check.hpp"

using craneassist::config::ConfigError;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const craneassist::config::CraneConfig cfg = craneassist::config::default_crane_config();
  static const std::filesystem::path base = CRANEASSIST_SOURCE_DIR "/examples/replays";
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto suite = craneassist::offline::parse_suite(text, "fuzz.yaml", base);
    for (const auto& run : suite.runs) {
      FUZZ_CHECK(std::filesystem::exists(run.replay), "a run's replay exists");
      FUZZ_CHECK(run.line > 0, "a run names its line");
    }
    try {
      craneassist::offline::check_suite(suite, cfg);
    } catch (const ConfigError& e) {
      FUZZ_CHECK(e.file() == "fuzz.yaml", "the pose error names the manifest");
    }
  } catch (const ConfigError& e) {
    FUZZ_CHECK(e.file() == "fuzz.yaml", "the error names the manifest");
    FUZZ_CHECK(e.line() >= 0, "a line number");
  }
  try {
    for (const auto& v : craneassist::offline::parse_variants(text, "fuzz.yaml", cfg)) {
      FUZZ_CHECK(!v.name.empty() && v.line > 0, "a variant has a name and a line");
      for (const auto& d : v.valves) {
        FUZZ_CHECK(
            std::isnan(d.time_constant_s) || (d.time_constant_s >= 0.0 && d.time_constant_s <= 5.0),
            "a spool lag in range");
        FUZZ_CHECK(std::isnan(d.dead_zone) || (d.dead_zone >= 0.0 && d.dead_zone <= 0.95),
                   "a dead band in range");
        FUZZ_CHECK(d.gain >= 0.1 && d.gain <= 10.0 && d.shape >= 0.2 && d.shape <= 5.0,
                   "a gain and a shape in range");
      }
    }
  } catch (const ConfigError& e) {
    FUZZ_CHECK(e.file() == "fuzz.yaml", "the variants error names the file");
  }
  return 0;
}
