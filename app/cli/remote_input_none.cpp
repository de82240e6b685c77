// A build without DDS (CRANEASSIST_DDS=OFF): no remote operator input.
#include <stdexcept>

#include "remote_input.hpp"

namespace craneassist::cli {

namespace {
constexpr const char* kNotBuilt =
    "this craneassist was built without DDS (CRANEASSIST_DDS=OFF): no --input dds";
}

bool remote_input_available() {
  return false;
}

void check_remote_input_settings(const config::TelemetryConfig&) {
  throw std::invalid_argument(kNotBuilt);
}

RemoteInput open_remote_input(const config::TelemetryConfig&, double) {
  throw std::runtime_error(kNotBuilt);
}

}  // namespace craneassist::cli
