#include "craneassist/input/command_source.hpp"

#include <chrono>

namespace craneassist::input {

const char* to_string(SourceState state) {
  switch (state) {
    case SourceState::kOk:
      return "ok";
    case SourceState::kNoData:
      return "no_data";
    case SourceState::kDisconnected:
      return "disconnected";
  }
  return "unknown";
}

double steady_now_s() noexcept {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace craneassist::input
