#include "exit_codes.hpp"

#include <spdlog/spdlog.h>

#include <exception>

#include "craneassist/config/config_error.hpp"
#include "craneassist/input/file_error.hpp"

namespace craneassist::cli {

int input_error_exit(const char* file_kind) {
  try {
    throw;
  } catch (const config::ConfigError& e) {
    spdlog::error("config: {}", e.what());
  } catch (const input::FileError& e) {
    spdlog::error("{}: {}", file_kind, e.what());
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
  return kExitUsage;
}

}  // namespace craneassist::cli
