// Exit codes of the craneassist command line, and the one way a subcommand reports an error in
// its inputs.
#pragma once

#include <string>

namespace craneassist::cli {

constexpr int kExitOk = 0;
constexpr int kExitUsage = 2;    // bad command line or input file (any format, any size)
constexpr int kExitRuntime = 3;  // the run itself failed

// Inside a catch block around reading a run's inputs (config, files, option values): logs the
// error in flight, a config error as "config: ...", an input file's as "<file_kind>: FILE:LINE:
// field ...: why", anything else as it is, and returns kExitUsage.
int input_error_exit(const char* file_kind);

// A subcommand's text result: to standard output when `path` is empty, else to the file, then
// logs "wrote PATH (what)". Returns kExitOk, or logs "PATH: cannot write" and returns
// kExitRuntime.
int write_output(const std::string& text, const std::string& path, const std::string& what);

}  // namespace craneassist::cli
