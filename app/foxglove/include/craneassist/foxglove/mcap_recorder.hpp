// `--mcap FILE` (replay, sim): the loop's cycles recorded as an MCAP file with the channels of
// channels.hpp, every cycle. A CycleObserver: on the loop thread it hands the cycle over
// (cycle_hand_over.hpp: no lock, no allocation, no I/O; a full ring drops the cycle and counts
// it); a writer thread encodes the messages and writes the chunks (McapWriter).
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>
#include <thread>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/foxglove/channels.hpp"
#include "craneassist/foxglove/cycle_hand_over.hpp"
#include "craneassist/foxglove/mcap_writer.hpp"

namespace craneassist::foxglove {

struct McapRecorderOptions {
  McapOptions file;
  std::size_t ring_rows = 1 << 12;
};

class McapRecorder : public control::CycleObserver {
 public:
  // Opens the file (throws std::runtime_error naming it) and starts the writer thread.
  McapRecorder(const std::filesystem::path& path, const dynamics::CraneModel& model, bool base,
               const McapRecorderOptions& options = {});
  ~McapRecorder() override;

  void on_cycle(const control::CycleRecord& cycle) noexcept override;
  // Writes what is left, the summary and the footer.
  void on_finish(const control::CycleTime& last, const valves::MachineState& state) override;

  // "  mcap: FILE, N messages on C channels in K chunks, B bytes (D cycles dropped)"
  std::string report() const;
  std::uint64_t dropped() const noexcept { return cycles_.dropped(); }
  McapStats stats() const;

 private:
  void run();
  void write_slot(const CycleHandOver::Slot& slot);
  void finish();

  McapRecorderOptions options_;
  ChannelSet channels_;
  McapWriter writer_;
  std::vector<std::uint16_t> ids_;
  std::vector<std::uint8_t> message_;
  CycleHandOver cycles_;
  bool description_written_ = false;
  std::atomic<bool> stop_{false};
  std::string error_;  // the writer thread's, after it stopped
  std::thread thread_;
};

}  // namespace craneassist::foxglove
