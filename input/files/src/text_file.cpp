#include "craneassist/files/text_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <system_error>
#include <utility>

namespace craneassist::files {
namespace {

std::string errno_text(int error) {
  return std::generic_category().message(error);
}

// Closes the descriptor when the read ends, however it ends.
class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

ReadError::ReadError(std::string file, std::string reason)
    : std::runtime_error(file + ": " + reason),
      file_(std::move(file)),
      reason_(std::move(reason)) {}

std::string size_text(std::size_t bytes) {
  if (bytes >= kMiB && bytes % kMiB == 0) return std::to_string(bytes / kMiB) + " MiB";
  return std::to_string(bytes) + " bytes";
}

std::string read_text_file(const std::filesystem::path& path, std::size_t max_bytes,
                           std::string_view kind) {
  const std::string name = path.string();
  const auto too_large = [&] {
    return ReadError(name, "larger than " + size_text(max_bytes) + " (the limit for " +
                               std::string(kind) + " files)");
  };
  const Descriptor fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) {
    const int error = errno;
    if (error == ENOENT) throw ReadError(name, "file not found");
    throw ReadError(name, "cannot open file: " + errno_text(error));
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) throw ReadError(name, "read error: " + errno_text(errno));
  if (S_ISDIR(st.st_mode)) throw ReadError(name, "cannot read file: is a directory");
  // A regular file states its size: refuse a large one before reading it. Anything else (a
  // device, a FIFO) is bounded by the read below, as is a regular file that grows meanwhile.
  std::string text;
  if (S_ISREG(st.st_mode)) {
    if (static_cast<std::uintmax_t>(st.st_size) > max_bytes) throw too_large();
    text.reserve(static_cast<std::size_t>(st.st_size));
  }
  constexpr std::size_t kChunk = std::size_t{1} << 16;
  char buffer[kChunk];
  while (true) {
    // One byte past the bound at most: enough to tell that the file is over it.
    const std::size_t want = std::min(kChunk, max_bytes + 1 - text.size());
    const ssize_t got = ::read(fd.get(), buffer, want);
    if (got < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      if (error == EISDIR) throw ReadError(name, "cannot read file: is a directory");
      throw ReadError(name, "read error: " + errno_text(error));
    }
    if (got == 0) break;
    text.append(buffer, static_cast<std::size_t>(got));
    if (text.size() > max_bytes) throw too_large();
  }
  return text;
}

}  // namespace craneassist::files
