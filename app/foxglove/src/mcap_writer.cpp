#include "craneassist/foxglove/mcap_writer.hpp"

#include <zstd.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <stdexcept>

namespace craneassist::foxglove {

namespace {

constexpr std::uint8_t kMagic[] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

// Little-endian fields into a record's bytes.
struct Bytes {
  std::vector<std::uint8_t>& b;
  template <class T>
  void le(T v) {
    std::uint8_t bytes[sizeof(T)];
    for (std::size_t i = 0; i < sizeof(T); ++i) bytes[i] = static_cast<std::uint8_t>(v >> (8 * i));
    raw(bytes, sizeof(T));
  }
  void u8(std::uint8_t v) { raw(&v, 1); }
  void u16(std::uint16_t v) { le(v); }
  void u32(std::uint32_t v) { le(v); }
  void u64(std::uint64_t v) { le(v); }
  void raw(const void* data, std::size_t size) {
    if (size == 0) return;
    const std::size_t at = b.size();
    b.resize(at + size);
    std::memcpy(b.data() + at, data, size);
  }
  void str(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    raw(s.data(), s.size());
  }
  // A record: opcode, content length, content (from `content`).
  void record(std::uint8_t op, const std::vector<std::uint8_t>& content) {
    u8(op);
    u64(content.size());
    raw(content.data(), content.size());
  }
};

std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1U) != 0 ? 0xEDB88320U ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}

}  // namespace

std::uint32_t crc32(std::uint32_t crc, const void* data, std::size_t size) noexcept {
  static const std::array<std::uint32_t, 256> table = make_crc_table();
  const auto* p = static_cast<const std::uint8_t*>(data);
  std::uint32_t c = ~crc;
  for (std::size_t i = 0; i < size; ++i) c = table[(c ^ p[i]) & 0xFFU] ^ (c >> 8);
  return ~c;
}

const char* to_string(McapCompression c) noexcept {
  return c == McapCompression::kZstd ? "zstd" : "none";
}

McapWriter::McapWriter(const std::filesystem::path& path, const McapOptions& options)
    : path_(path), options_(options) {
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) {
    throw std::runtime_error(path.string() + ": cannot open the MCAP file for writing");
  }
  if (options_.compression == McapCompression::kZstd) zstd_ = ZSTD_createCCtx();
  std::vector<std::uint8_t> bytes(std::begin(kMagic), std::end(kMagic)), header;
  Bytes h{header};
  h.str("");  // no profile (see the header)
  h.str("craneassist");
  Bytes{bytes}.record(kHeader, header);
  put(bytes);
  chunk_.reserve(options_.chunk_bytes + (64 << 10));
  sequence_.push_back(0);  // channel ids start at 1
}

McapWriter::~McapWriter() {
  try {
    close();
  } catch (...) {  // a destructor reports nothing; close() reports its errors
  }
  if (zstd_ != nullptr) ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(zstd_));
}

void McapWriter::put(const std::vector<std::uint8_t>& bytes) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    throw std::runtime_error(path_.string() + ": cannot write the MCAP file");
  }
  data_crc_ = crc32(data_crc_, bytes.data(), bytes.size());
  offset_ += bytes.size();
  stats_.bytes = offset_;
}

std::uint16_t McapWriter::add_channel(const Channel& channel) {
  const auto id = static_cast<std::uint16_t>(sequence_.size());
  std::vector<std::uint8_t> content, record;
  Bytes s{content};
  s.u16(id);  // one schema per channel, the same id
  s.str(channel.schema_name);
  s.str(channel.schema_encoding);
  s.str(channel.schema);
  Bytes{record}.record(kSchema, content);
  schema_records_.push_back(record);
  put(record);
  content.clear();
  record.clear();
  Bytes c{content};
  c.u16(id);
  c.u16(id);
  c.str(channel.topic);
  c.str(channel.message_encoding);
  std::vector<std::uint8_t> metadata;
  Bytes m{metadata};
  if (channel.latched) {
    // What ros2 bag and Foxglove read as a latched (transient local) topic.
    m.str("offered_qos_profiles");
    m.str("- history: 3\n  depth: 0\n  reliability: 1\n  durability: 1\n");
  }
  c.u32(static_cast<std::uint32_t>(metadata.size()));
  c.raw(metadata.data(), metadata.size());
  Bytes{record}.record(kChannel, content);
  channel_records_.push_back(record);
  put(record);
  sequence_.push_back(0);
  channel_counts_[id] = 0;
  return id;
}

void McapWriter::write(std::uint16_t channel_id, std::uint64_t log_time_ns,
                       const std::uint8_t* data, std::size_t size) {
  if (file_ == nullptr || channel_id == 0 || channel_id >= sequence_.size()) return;
  if (!chunk_.empty() && (chunk_.size() >= options_.chunk_bytes ||
                          log_time_ns - chunk_start_ns_ >= options_.chunk_duration_ns)) {
    flush_chunk();
  }
  if (chunk_index_.empty()) {
    chunk_start_ns_ = log_time_ns;
    chunk_end_ns_ = log_time_ns;
  }
  chunk_start_ns_ = std::min(chunk_start_ns_, log_time_ns);
  chunk_end_ns_ = std::max(chunk_end_ns_, log_time_ns);
  chunk_index_[channel_id].emplace_back(log_time_ns, chunk_.size());
  Bytes b{chunk_};
  b.u8(kMessage);
  b.u64(2 + 4 + 8 + 8 + size);
  b.u16(channel_id);
  b.u32(sequence_[channel_id]++);
  b.u64(log_time_ns);
  b.u64(log_time_ns);
  b.raw(data, size);
  if (stats_.messages == 0) start_ns_ = end_ns_ = log_time_ns;
  start_ns_ = std::min(start_ns_, log_time_ns);
  end_ns_ = std::max(end_ns_, log_time_ns);
  ++stats_.messages;
  ++channel_counts_[channel_id];
}

void McapWriter::flush_chunk() {
  if (chunk_.empty()) return;
  const std::uint32_t crc = crc32(0, chunk_.data(), chunk_.size());
  const std::uint8_t* records = chunk_.data();
  std::size_t records_size = chunk_.size();
  if (zstd_ != nullptr) {
    compressed_.resize(ZSTD_compressBound(chunk_.size()));
    const std::size_t n =
        ZSTD_compressCCtx(static_cast<ZSTD_CCtx*>(zstd_), compressed_.data(), compressed_.size(),
                          chunk_.data(), chunk_.size(), options_.zstd_level);
    if (ZSTD_isError(n) != 0U) {
      throw std::runtime_error(path_.string() + ": zstd: " + ZSTD_getErrorName(n));
    }
    records = compressed_.data();
    records_size = n;
  }
  ChunkIndex index{chunk_start_ns_, chunk_end_ns_, offset_, 0, 0, records_size, chunk_.size(), {}};
  record_.clear();
  Bytes r{record_};
  r.u8(kChunk);
  const std::string compression = zstd_ != nullptr ? "zstd" : "";
  r.u64(8 + 8 + 8 + 4 + 4 + compression.size() + 8 + records_size);
  r.u64(chunk_start_ns_);
  r.u64(chunk_end_ns_);
  r.u64(chunk_.size());
  r.u32(crc);
  r.str(compression);
  r.u64(records_size);
  r.raw(records, records_size);
  index.length = record_.size();
  // The message indexes, in channel order, right after the chunk.
  std::uint64_t at = offset_ + record_.size();
  for (const auto& [channel, entries] : chunk_index_) {
    const std::size_t start = record_.size();
    r.u8(kMessageIndex);
    r.u64(2 + 4 + 16 * entries.size());
    r.u16(channel);
    r.u32(static_cast<std::uint32_t>(16 * entries.size()));
    for (const auto& [t, off] : entries) {
      r.u64(t);
      r.u64(off);
    }
    index.index_offsets[channel] = at;
    at += record_.size() - start;
    index.index_length += record_.size() - start;
  }
  put(record_);
  std::fflush(file_);
  chunks_.push_back(std::move(index));
  ++stats_.chunks;
  chunk_.clear();
  chunk_index_.clear();
}

void McapWriter::close() {
  if (file_ == nullptr) return;
  flush_chunk();
  std::vector<std::uint8_t> bytes, content;
  Bytes{content}.u32(data_crc_);
  Bytes{bytes}.record(kDataEnd, content);
  put(bytes);
  // The summary: schemas, channels, statistics, chunk indexes (each group's place recorded).
  const std::uint64_t summary_start = offset_;
  std::vector<std::uint8_t> summary, offsets;
  std::vector<std::array<std::uint64_t, 3>> groups;  // opcode, start, length
  const auto group = [&](std::uint8_t op, const auto& emit) {
    const std::size_t start = summary.size();
    emit();
    if (summary.size() > start) {
      groups.push_back({op, summary_start + start, summary.size() - start});
    }
  };
  group(kSchema, [&] {
    for (const auto& r : schema_records_) summary.insert(summary.end(), r.begin(), r.end());
  });
  group(kChannel, [&] {
    for (const auto& r : channel_records_) summary.insert(summary.end(), r.begin(), r.end());
  });
  group(kStatistics, [&] {
    content.clear();
    Bytes s{content};
    s.u64(stats_.messages);
    s.u16(static_cast<std::uint16_t>(schema_records_.size()));
    s.u32(static_cast<std::uint32_t>(channel_records_.size()));
    s.u32(0);  // attachments
    s.u32(0);  // metadata
    s.u32(static_cast<std::uint32_t>(chunks_.size()));
    s.u64(stats_.messages > 0 ? start_ns_ : 0);
    s.u64(stats_.messages > 0 ? end_ns_ : 0);
    s.u32(static_cast<std::uint32_t>(channel_counts_.size() * 10));
    for (const auto& [id, n] : channel_counts_) {
      s.u16(id);
      s.u64(n);
    }
    Bytes{summary}.record(kStatistics, content);
  });
  group(kChunkIndex, [&] {
    for (const ChunkIndex& c : chunks_) {
      content.clear();
      Bytes s{content};
      s.u64(c.start_ns);
      s.u64(c.end_ns);
      s.u64(c.offset);
      s.u64(c.length);
      s.u32(static_cast<std::uint32_t>(c.index_offsets.size() * 10));
      for (const auto& [id, off] : c.index_offsets) {
        s.u16(id);
        s.u64(off);
      }
      s.u64(c.index_length);
      s.str(zstd_ != nullptr ? "zstd" : "");
      s.u64(c.compressed);
      s.u64(c.uncompressed);
      Bytes{summary}.record(kChunkIndex, content);
    }
  });
  const std::uint64_t summary_offset_start = summary_start + summary.size();
  for (const auto& g : groups) {
    content.clear();
    Bytes s{content};
    s.u8(static_cast<std::uint8_t>(g[0]));
    s.u64(g[1]);
    s.u64(g[2]);
    Bytes{offsets}.record(kSummaryOffset, content);
  }
  std::vector<std::uint8_t> footer;
  Bytes f{footer};
  f.u8(kFooter);
  f.u64(8 + 8 + 4);
  f.u64(summary_start);
  f.u64(summary_offset_start);
  std::uint32_t crc = crc32(0, summary.data(), summary.size());
  crc = crc32(crc, offsets.data(), offsets.size());
  crc = crc32(crc, footer.data(), footer.size());
  f.u32(crc);
  f.raw(kMagic, sizeof kMagic);
  put(summary);
  put(offsets);
  put(footer);
  const bool ok = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok) throw std::runtime_error(path_.string() + ": cannot close the MCAP file");
}

}  // namespace craneassist::foxglove
