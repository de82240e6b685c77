// An MCAP file writer (https://mcap.dev/spec, version 0): schemas and channels first in the data
// section, then chunks of messages (zstd-compressed, each with its CRC) each followed by its
// message indexes; at close the summary (schemas, channels, statistics, chunk indexes), the
// summary offsets and the footer, with the data section's and the summary's CRCs. What Foxglove's
// and PlotJuggler's indexed readers need to open a file at once and seek in it.
//
// Each chunk is written and flushed as soon as it is full (chunk_bytes) or spans chunk_duration
// of log time: a run that is killed leaves a file whose complete chunks a stream reader reads
// back (only the summary is missing). Not thread-safe: one thread writes (McapRecorder's).
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "craneassist/foxglove/channels.hpp"

namespace craneassist::foxglove {

enum class McapCompression { kZstd, kNone };
// "zstd", "none" (the MCAP record's compression: "zstd", "").
const char* to_string(McapCompression c) noexcept;

struct McapOptions {
  McapCompression compression = McapCompression::kZstd;
  std::size_t chunk_bytes = 1 << 20;                // uncompressed records per chunk, at most about
  std::uint64_t chunk_duration_ns = 1'000'000'000;  // log time a chunk spans, at most
  int zstd_level = 3;
};

struct McapStats {
  std::uint64_t messages = 0;
  std::uint64_t chunks = 0;
  std::uint64_t bytes = 0;  // written so far (the whole file after close())
};

// The CRC-32 (IEEE 802.3, as zlib's crc32) MCAP uses, continued from `crc` (0 to start).
std::uint32_t crc32(std::uint32_t crc, const void* data, std::size_t size) noexcept;

class McapWriter {
 public:
  // Creates the file and writes the magic and the header. No profile: the "ros2" profile asks for
  // cdr channels only, and the field table's channels are JSON (the cdr ones are ROS 2 messages
  // all the same, with ros2msg schemas). Throws std::runtime_error naming the file when it
  // cannot.
  McapWriter(const std::filesystem::path& path, const McapOptions& options);
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Writes the channel's schema and channel records; returns its channel id (1, 2, ...). Before
  // the first message.
  std::uint16_t add_channel(const Channel& channel);
  // One message (log time = publish time). Throws std::runtime_error on a write error.
  void write(std::uint16_t channel_id, std::uint64_t log_time_ns, const std::uint8_t* data,
             std::size_t size);
  // The last chunk, the data end, the summary and the footer; closes the file. Idempotent.
  void close();

  const McapStats& stats() const noexcept { return stats_; }
  const std::filesystem::path& path() const noexcept { return path_; }

 private:
  struct ChunkIndex {
    std::uint64_t start_ns, end_ns, offset, length, index_length, compressed, uncompressed;
    std::map<std::uint16_t, std::uint64_t> index_offsets;
  };
  void put(const std::vector<std::uint8_t>& bytes);  // to the file, counted in the data CRC
  void flush_chunk();

  std::filesystem::path path_;
  McapOptions options_;
  std::FILE* file_ = nullptr;
  std::uint64_t offset_ = 0;
  std::uint32_t data_crc_ = 0;
  std::vector<std::vector<std::uint8_t>> schema_records_, channel_records_;
  // The open chunk: its records, and per channel the (log time, offset) of its messages.
  std::vector<std::uint8_t> chunk_;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::uint64_t chunk_start_ns_ = 0, chunk_end_ns_ = 0;
  std::vector<std::uint8_t> compressed_, record_;
  void* zstd_ = nullptr;  // ZSTD_CCtx
  std::vector<ChunkIndex> chunks_;
  std::map<std::uint16_t, std::uint64_t> channel_counts_;
  std::vector<std::uint32_t> sequence_;  // per channel id
  std::uint64_t start_ns_ = 0, end_ns_ = 0;
  McapStats stats_;
};

}  // namespace craneassist::foxglove
