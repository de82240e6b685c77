#include "craneassist/input/command_source.hpp"

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

}  // namespace craneassist::input
