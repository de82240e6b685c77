#include "exit_codes.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <exception>
#include <fstream>

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

int write_output(const std::string& text, const std::string& path, const std::string& what) {
  if (path.empty()) {
    std::fputs(text.c_str(), stdout);
    return kExitOk;
  }
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) {
    spdlog::error("{}: cannot write", path);
    return kExitRuntime;
  }
  spdlog::info("wrote {} ({})", path, what);
  return kExitOk;
}

}  // namespace craneassist::cli
