// Exit codes of the craneassist command line.
#pragma once

namespace craneassist::cli {

constexpr int kExitOk = 0;
constexpr int kExitUsage = 2;    // bad command line, config, replay, path or trajectory file
constexpr int kExitRuntime = 3;  // the run itself failed

}  // namespace craneassist::cli
