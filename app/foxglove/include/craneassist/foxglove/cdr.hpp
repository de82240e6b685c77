// A little-endian CDR (XCDR1, plain) writer for the ROS 2 messages of the Foxglove channels and
// MCAP recordings: what rmw puts on the wire, and what Foxglove's and PlotJuggler's "cdr"
// decoders read. Alignment is counted from the end of the 4-byte encapsulation header. Appends to
// a caller's buffer (no allocation once it has grown to a message's size).
#pragma once

#include <cstdint>
#include <cstring>
#include <string_view>
#include <vector>

namespace craneassist::foxglove {

class CdrWriter {
 public:
  explicit CdrWriter(std::vector<std::uint8_t>& out) : out_(out) {
    out_.assign(4, 0);
    out_[1] = 0x01;  // CDR_LE, no options
  }

  void u32(std::uint32_t v) { put(&v, sizeof v); }
  void i32(std::int32_t v) { put(&v, sizeof v); }
  void f64(double v) { put(&v, sizeof v); }
  // A string: its length with the terminating NUL, the bytes, the NUL.
  void str(std::string_view s) {
    u32(static_cast<std::uint32_t>(s.size() + 1));
    out_.insert(out_.end(), s.begin(), s.end());
    out_.push_back(0);
  }
  // A sequence's element count (the elements follow).
  void count(std::size_t n) { u32(static_cast<std::uint32_t>(n)); }

 private:
  template <class T>
  void put(const T* v, std::size_t size) {
    const std::size_t offset = out_.size() - 4;
    out_.resize(out_.size() + (size - offset % size) % size, 0);  // align to the size
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(v);
    out_.insert(out_.end(), bytes, bytes + size);
  }
  std::vector<std::uint8_t>& out_;
};

}  // namespace craneassist::foxglove
