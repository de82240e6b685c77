#include "craneassist/foxglove/mcap_recorder.hpp"

#include <chrono>
#include <cmath>
#include <exception>

namespace craneassist::foxglove {

McapRecorder::McapRecorder(const std::filesystem::path& path, const dynamics::CraneModel& model,
                           bool base, const McapRecorderOptions& options)
    : options_(options),
      channels_(model, base),
      writer_(path, options.file),
      cycles_(options.ring_rows) {
  for (const Channel& c : channels_.channels()) ids_.push_back(writer_.add_channel(c));
  message_.reserve(1 << 16);
  thread_ = std::thread([this] { run(); });
}

McapRecorder::~McapRecorder() {
  try {
    finish();
  } catch (...) {  // reported by on_finish() when the run ends normally
  }
}

void McapRecorder::on_cycle(const control::CycleRecord& cycle) noexcept {
  cycles_.push(cycle);
}

void McapRecorder::write_slot(const CycleHandOver::Slot& slot) {
  const std::uint64_t t_ns = cycles_.time_ns(slot.t_s);
  const auto stamp = static_cast<std::int64_t>(t_ns);
  for (std::size_t k = 0; k < channels_.size(); ++k) {
    if (channels_.channels()[k].latched) {
      if (description_written_) continue;
    }
    channels_.encode(k, slot.row, stamp, message_);
    writer_.write(ids_[k], t_ns, message_.data(), message_.size());
  }
  description_written_ = true;
}

void McapRecorder::run() {
  try {
    for (;;) {
      const bool stopping = stop_.load(std::memory_order_acquire);
      while (const CycleHandOver::Slot* slot = cycles_.front()) {
        write_slot(*slot);
        cycles_.pop();
      }
      if (stopping) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    writer_.close();
  } catch (const std::exception& e) {
    error_ = e.what();
  }
}

void McapRecorder::finish() {
  if (!thread_.joinable()) return;
  stop_.store(true, std::memory_order_release);
  thread_.join();
  if (!error_.empty()) throw std::runtime_error(error_);
}

void McapRecorder::on_finish(const control::CycleTime&, const valves::MachineState&) {
  finish();
}

McapStats McapRecorder::stats() const {
  return writer_.stats();
}

std::string McapRecorder::report() const {
  const McapStats s = writer_.stats();
  return "  mcap: " + writer_.path().string() + ", " + std::to_string(s.messages) +
         " messages on " + std::to_string(channels_.size()) + " channels in " +
         std::to_string(s.chunks) + " chunks, " + std::to_string(s.bytes) + " bytes (" +
         std::to_string(cycles_.dropped()) + " cycles dropped)";
}

}  // namespace craneassist::foxglove
