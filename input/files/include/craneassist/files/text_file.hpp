// The one way craneassist reads a file it is given: the whole text, with a size bound. Every
// outside file (YAML configs and mappings, suite manifests, CSV replays, tip paths and joint
// trajectories) is read here, so that a huge file, /dev/zero or a FIFO that never ends is
// refused at the bound instead of growing the process until the memory runs out.
#pragma once

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace craneassist::files {

inline constexpr std::size_t kMiB = std::size_t{1} << 20;
// The limits by kind (docs/config.md, docs/replay-format.md): a YAML file (crane config,
// joystick mapping, telemetry config, CAN mapping, suite manifest) is a few kB; a CSV file
// (replay, tip path, joint trajectory) of 64 MiB holds about a million rows, hours of a 100 Hz
// recording.
inline constexpr std::size_t kMaxYamlBytes = 1 * kMiB;
inline constexpr std::size_t kMaxCsvBytes = 64 * kMiB;
// A DBC file (CAN database) of a whole vehicle runs to a few hundred kB.
inline constexpr std::size_t kMaxDbcBytes = 4 * kMiB;

// A file that could not be read, or is over its limit. what() is "FILE: REASON"; the readers of
// the file formats turn it into their own error (config::ConfigError, input::FileError).
class ReadError : public std::runtime_error {
 public:
  ReadError(std::string file, std::string reason);

  const std::string& file() const noexcept { return file_; }
  const std::string& reason() const noexcept { return reason_; }

 private:
  std::string file_;
  std::string reason_;
};

// The contents of `path`, at most max_bytes of them. `kind` names what the file is for the
// message over the limit ("crane config": "larger than 1 MiB (the limit for crane config files)").
// Reads in chunks and stops one byte past the bound, so a file whose size stat() cannot tell
// (/dev/zero, a FIFO, a file still growing) is bounded too. Throws ReadError with the reason:
// "file not found", "cannot open file: REASON", "cannot read file: is a directory",
// "read error: REASON", "larger than N MiB (the limit for KIND files)".
std::string read_text_file(const std::filesystem::path& path, std::size_t max_bytes,
                           std::string_view kind);

// "1 MiB", "64 MiB", "1000 bytes": a limit as the messages write it.
std::string size_text(std::size_t bytes);

}  // namespace craneassist::files
