#include "craneassist/dds/command_source.hpp"

#include <array>
#include <atomic>
#include <cmath>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/SubscriberQos.hpp>
#include <mutex>
#include <stdexcept>

#include "checked_types.hpp"
#include "command_participant.hpp"
#include "craneassist_msgs.h"
#include "participant.hpp"

namespace craneassist::dds {

namespace fdds = eprosima::fastdds::dds;

void check_command_input_settings(const config::TelemetryConfig& settings) {
  std::string missing = missing_security_files(settings.commands.security);
  if (!settings.commands.enabled) {
    missing = "commands.enabled is not true" + (missing.empty() ? "" : ", " + missing);
  }
  if (!missing.empty()) {
    throw std::invalid_argument(
        "the DDS command input needs `commands.enabled: true` and every commands.security file "
        "in the DDS settings given with --telemetry-config FILE; in " +
        settings.source_name + ": " + missing +
        ". tools/dds-security/make-certs.sh makes certificates and settings files "
        "(docs/remote-commands.md)");
  }
}

struct DdsCommandSource::Impl : public fdds::DataReaderListener {
  Impl(const config::TelemetryConfig& settings, double stale_timeout_s)
      : start_s(input::steady_now_s()), takeover_silence_s(stale_timeout_s) {
    if (!(stale_timeout_s > 0.0)) {
      throw std::invalid_argument("DdsCommandSource: the stale timeout must be positive");
    }
    check_command_input_settings(settings);
    ParticipantOptions options = participant_options(settings);
    options.name = settings.participant_name + "-commands";
    options.security = settings.commands.security;
    participant = make_participant(options);
    fdds::Subscriber* subscriber = participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    if (subscriber == nullptr) throw std::runtime_error("DDS: cannot create the subscriber");
    reader = subscriber->create_datareader(get_topic(*participant, Topic::kOperatorCommand),
                                           reader_qos(settings.commands.topic), this,
                                           fdds::StatusMask::all());
    if (reader == nullptr) {
      throw std::runtime_error(
          "DDS Security: cannot create the reader of craneassist/operator_command (do the "
          "crane's permissions allow subscribing to it? Fast DDS logs the reason above)");
    }
  }

  ~Impl() override {
    // Deletes the reader (no more callbacks) before the listener's members go.
    participant.reset();
  }

  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  // Fast DDS's listener thread.
  void on_data_available(fdds::DataReader* r) override {
    std::lock_guard<std::mutex> lock(listener_mutex);
    fdds::SampleInfo info;
    // A malformed sample is dropped and counted: it counts as missing (the input goes stale).
    std::uint64_t bad = 0;
    while (take_next_valid(*r, &sample, info, bad)) accept(info.publication_handle);
    if (bad > 0) malformed.fetch_add(bad, std::memory_order_relaxed);
  }

  void on_subscription_matched(fdds::DataReader*,
                               const fdds::SubscriptionMatchedStatus& s) override {
    if (s.current_count_change > 0) {
      writer_matches.fetch_add(s.current_count_change, std::memory_order_relaxed);
      if (first_match_s.load(std::memory_order_relaxed) < 0.0) {
        first_match_s.store(input::steady_now_s() - start_s, std::memory_order_relaxed);
      }
      if (s.current_count > peak_matched.load(std::memory_order_relaxed)) {
        peak_matched.store(s.current_count, std::memory_order_relaxed);
      }
    }
    if (s.current_count_change < 0) {
      // A writer gone, the operator's too: it is silent from now on, and another writer takes the
      // command over by the same rule as from a silent one (accept()).
      std::lock_guard<std::mutex> lock(listener_mutex);
      forget_writer(s.last_publication_handle);
    }
    if (s.current_count > 0) ever_matched.store(true, std::memory_order_release);
    matched.store(s.current_count, std::memory_order_release);
  }

  // True when `sample_seq` is above every seq `writer` sent before (and records it): a sample
  // with an older or the same seq is a replay (or a repeat), whoever holds the command.
  bool fresh_seq(const fdds::InstanceHandle_t& writer, std::uint64_t sample_seq, double now) {
    WriterSeq* slot = nullptr;
    WriterSeq* free_slot = nullptr;
    WriterSeq* oldest = nullptr;
    for (WriterSeq& e : writer_seqs) {
      if (e.used && e.writer == writer) {
        slot = &e;
        break;
      }
      if (!e.used) {
        if (free_slot == nullptr) free_slot = &e;
      } else if (!(has_owner && e.writer == owner) &&
                 (oldest == nullptr || e.heard_s < oldest->heard_s)) {
        oldest = &e;
      }
    }
    if (slot != nullptr) {
      if (sample_seq <= slot->seq) return false;
    } else {
      // A writer not heard from before; when every entry is taken, the writer heard from
      // longest ago (never the operator holding the command) makes room.
      slot = free_slot != nullptr ? free_slot : oldest;
      if (slot == nullptr) return true;
      slot->used = true;
      slot->writer = writer;
    }
    slot->seq = sample_seq;
    slot->heard_s = now;
    return true;
  }

  void forget_writer(const fdds::InstanceHandle_t& writer) {
    for (WriterSeq& e : writer_seqs) {
      if (e.used && e.writer == writer) e.used = false;
    }
  }

  void accept(const fdds::InstanceHandle_t& writer) {
    const double now = input::steady_now_s();
    if (!fresh_seq(writer, sample.seq(), now)) {
      replayed.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    // One operator at a time: another writer takes the command over only once the operator
    // holding it has been silent for longer than the stale timeout (the monitor has stopped the
    // crane on stale input by then), never while it sends.
    if (has_owner && writer != owner && !(now - owner_last_s > takeover_silence_s)) {
      other_senders.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    if (!has_owner || writer != owner) {
      owner = writer;
      has_owner = true;
      owner_released = false;
      last_seq_valid = false;
      owner_changes.fetch_add(1, std::memory_order_relaxed);
    }
    owner_last_s = now;
    // A new operator's deadman counts only after it has sent it released: until then the
    // deadman reads released, so the monitor sees a release and then its press (re-arm), even
    // when it never saw the old operator's samples go stale.
    if (!sample.deadman()) owner_released = true;
    const bool deadman_held = sample.deadman() && owner_released;
    if (last_seq_valid && sample.seq() > last_seq + 1) {
      lost.fetch_add(sample.seq() - last_seq - 1, std::memory_order_relaxed);
    }
    last_seq = sample.seq();
    last_seq_valid = true;
    const std::array<double, 3>& v = sample.v_m_s();
    if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]))) {
      non_finite.fetch_add(1, std::memory_order_relaxed);
    }
    // Seqlock write (single writer: this thread).
    const std::uint32_t s = seq.load(std::memory_order_relaxed);
    seq.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    stamp.store(now, std::memory_order_relaxed);
    vx.store(v[0], std::memory_order_relaxed);
    vy.store(v[1], std::memory_order_relaxed);
    vz.store(v[2], std::memory_order_relaxed);
    deadman.store(deadman_held, std::memory_order_relaxed);
    seq.store(s + 2, std::memory_order_release);
    have_sample.store(true, std::memory_order_release);
    if (samples.fetch_add(1, std::memory_order_relaxed) == 0) {
      first_sample_s.store(now - start_s, std::memory_order_relaxed);
    }
    if (sample.sender() != sender_seen) {
      sender_seen = sample.sender();
      std::lock_guard<std::mutex> lock(sender_mutex);
      sender = sender_seen;
    }
  }

  // The loop thread.
  input::SourceState poll(input::OperatorCommand& out) noexcept {
    const bool gone = ever_matched.load(std::memory_order_acquire) &&
                      matched.load(std::memory_order_acquire) == 0;
    if (!have_sample.load(std::memory_order_acquire)) {
      return gone ? input::SourceState::kDisconnected : input::SourceState::kNoData;
    }
    // Seqlock read, a bounded number of tries: when the listener keeps writing, the previous copy
    // (with its older stamp) is returned, so poll() never waits.
    for (int attempt = 0; attempt < 4; ++attempt) {
      const std::uint32_t s1 = seq.load(std::memory_order_acquire);
      if (s1 & 1U) continue;
      const double t = stamp.load(std::memory_order_relaxed);
      const double x = vx.load(std::memory_order_relaxed);
      const double y = vy.load(std::memory_order_relaxed);
      const double z = vz.load(std::memory_order_relaxed);
      const bool d = deadman.load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq.load(std::memory_order_relaxed) != s1) continue;
      latest.stamp_s = t;
      latest.v_m_s = Eigen::Vector3d(x, y, z);
      latest.deadman = d;
      break;
    }
    out = latest;
    return gone ? input::SourceState::kDisconnected : input::SourceState::kOk;
  }

  CommandInputStats stats() const {
    CommandInputStats s;
    s.samples = samples.load();
    s.non_finite = non_finite.load();
    s.malformed = malformed.load();
    s.replayed = replayed.load();
    s.owner_changes = owner_changes.load();
    s.lost = lost.load();
    s.other_senders = other_senders.load();
    s.matched_writers = matched.load();
    s.peak_matched_writers = peak_matched.load();
    s.writer_matches = writer_matches.load();
    s.first_match_s = first_match_s.load();
    s.first_sample_s = first_sample_s.load();
    std::lock_guard<std::mutex> lock(sender_mutex);
    s.sender = sender;
    return s;
  }

  const double start_s;
  const double takeover_silence_s;  // the monitor's stale timeout
  // The latest sample (seqlock: the listener writes, poll() reads).
  std::atomic<std::uint32_t> seq{0};
  std::atomic<double> stamp{0.0}, vx{0.0}, vy{0.0}, vz{0.0};
  std::atomic<bool> deadman{false};
  std::atomic<bool> have_sample{false};
  std::atomic<int> matched{0};
  std::atomic<bool> ever_matched{false};
  // Counters.
  std::atomic<std::uint64_t> samples{0}, non_finite{0}, lost{0}, other_senders{0}, malformed{0},
      replayed{0};
  std::atomic<int> peak_matched{0}, writer_matches{0}, owner_changes{0};
  std::atomic<double> first_match_s{-1.0}, first_sample_s{-1.0};
  mutable std::mutex sender_mutex;
  std::string sender;
  // Fast DDS's threads (data and discovery), under listener_mutex; the loop never takes it.
  std::mutex listener_mutex;
  craneassist::msg::OperatorCommand sample;
  fdds::InstanceHandle_t owner;
  bool has_owner = false;
  double owner_last_s = 0.0;
  bool owner_released = false;  // the operator holding the command has sent its deadman released
  std::uint64_t last_seq = 0;   // the operator's, for `lost`
  bool last_seq_valid = false;
  // The highest seq of each writer heard from (fresh_seq); an entry goes when its writer is
  // unmatched.
  struct WriterSeq {
    fdds::InstanceHandle_t writer;
    std::uint64_t seq = 0;
    double heard_s = 0.0;
    bool used = false;
  };
  std::array<WriterSeq, 16> writer_seqs{};
  std::string sender_seen;
  // Loop thread only.
  input::OperatorCommand latest;
  // DDS entities.
  ParticipantPtr participant;
  fdds::DataReader* reader = nullptr;
};

DdsCommandSource::DdsCommandSource(const config::TelemetryConfig& settings, double stale_timeout_s)
    : impl_(std::make_unique<Impl>(settings, stale_timeout_s)) {}

DdsCommandSource::~DdsCommandSource() = default;

input::SourceState DdsCommandSource::poll(input::OperatorCommand& out) noexcept {
  return impl_->poll(out);
}

CommandInputStats DdsCommandSource::stats() const {
  return impl_->stats();
}

}  // namespace craneassist::dds
