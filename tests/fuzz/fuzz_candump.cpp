// candump log lines (can::parse_candump, can/can_frame.hpp; the --can-log files and what the VM
// tests read back): any bytes, split into lines, are parsed; a line that parses is a valid frame,
// and formatting the record gives a line that parses to the same record. The first input byte
// also drives format_candump directly with an arbitrary frame and interface name.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

#include "craneassist/can/can_frame.hpp"
#include "fuzz_check.hpp"

namespace can = craneassist::can;

namespace {

void check_line(std::string_view line) {
  can::CandumpRecord record;
  const can::CandumpStatus status = can::parse_candump(line, record);
  (void)can::to_string(status);
  if (status != can::CandumpStatus::kOk) return;
  FUZZ_CHECK(can::is_valid(record.frame), "a parsed frame is valid");
  FUZZ_CHECK(record.timestamp >= 0, "a timestamp >= 0");
  FUZZ_CHECK(!record.iface.empty() && record.iface.size() <= can::kMaxInterfaceLength,
             "an interface name");
  FUZZ_CHECK(record.iface.data() >= line.data() &&
                 record.iface.data() + record.iface.size() <= line.data() + line.size(),
             "the interface points into the line");

  char out[can::kCandumpLineCapacity];
  std::size_t written = 0;
  const can::CandumpStatus formatted =
      can::format_candump(record.frame, record.timestamp, record.iface, out, written);
  FUZZ_CHECK(formatted == can::CandumpStatus::kOk, "a parsed record formats");
  FUZZ_CHECK(written > 0 && written < sizeof out && out[written] == '\0', "NUL-terminated line");
  can::CandumpRecord again;
  FUZZ_CHECK(can::parse_candump(std::string_view(out, written), again) == can::CandumpStatus::kOk,
             "a formatted line parses");
  FUZZ_CHECK(again.timestamp == record.timestamp && again.iface == record.iface &&
                 can::same_frame(again.frame, record.frame) &&
                 again.frame.extended == record.frame.extended,
             "parse -> format -> parse gives the same record");
}

// format_candump on a frame and interface made of the bytes (may be invalid).
void check_format(const std::uint8_t* data, std::size_t size) {
  if (size < 23) return;
  can::CanFrame frame;
  std::memcpy(&frame.id, data, 4);
  frame.extended = (data[4] & 1) != 0;
  frame.dlc = data[5];
  std::memcpy(frame.data.data(), data + 6, 8);
  std::int64_t timestamp = 0;
  std::memcpy(&timestamp, data + 14, 8);
  const std::size_t capacity = data[22] % (can::kCandumpLineCapacity + 8);
  const std::string_view iface(reinterpret_cast<const char*>(data + 23),
                               size - 23 > 20 ? 20 : size - 23);
  char out[can::kCandumpLineCapacity + 8];
  std::size_t written = 99;
  const can::CandumpStatus status =
      can::format_candump(frame, timestamp, iface, std::span<char>(out, capacity), written);
  if (status == can::CandumpStatus::kOk) {
    FUZZ_CHECK(can::is_valid(frame), "only a valid frame formats");
    FUZZ_CHECK(written < capacity && out[written] == '\0', "within the buffer, NUL-terminated");
    can::CandumpRecord back;
    FUZZ_CHECK(can::parse_candump(std::string_view(out, written), back) == can::CandumpStatus::kOk,
               "a formatted line parses");
    FUZZ_CHECK(
        back.timestamp == timestamp && back.iface == iface && can::same_frame(back.frame, frame),
        "format -> parse gives the same record");
  } else {
    FUZZ_CHECK(written == 0, "nothing written on failure");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 0 && data[0] == 0xFF) {
    check_format(data + 1, size - 1);
    return 0;
  }
  std::string_view text(reinterpret_cast<const char*>(data), size);
  check_line(text);  // the whole input as one line, then line by line
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    check_line(text.substr(0, end == std::string_view::npos ? text.size() : end + 1));
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  return 0;
}
