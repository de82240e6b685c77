// The telemetry of `sim` and `replay` (telemetry_setup.hpp) in a build without DDS
// (CRANEASSIST_DDS=OFF): the run goes on without it and says so.
#include <spdlog/spdlog.h>

#include "exit_codes.hpp"
#include "telemetry_setup.hpp"

namespace craneassist::cli {

struct Telemetry::Publishing {};

Telemetry::Telemetry() = default;
Telemetry::~Telemetry() = default;

control::CycleObserver* Telemetry::observer() {
  return nullptr;
}

int Telemetry::open(const config::TelemetryConfig& settings, bool wanted,
                    const config::CraneConfig&, const char*) {
  if (wanted && settings.enabled) {
    spdlog::warn("telemetry: this craneassist was built without DDS (CRANEASSIST_DDS=OFF)");
  }
  return kExitOk;
}

void Telemetry::finish() {}

}  // namespace craneassist::cli
