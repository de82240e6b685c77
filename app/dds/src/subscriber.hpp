// The subscriber side shared by `craneassist echo` and `craneassist dashboard` (internal to the
// dds module: Fast DDS types, C++17): a participant with one best-effort, volatile reader per
// topic (matches every writer), listeners that record discovery and wake the waiting thread.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "craneassist/dds/topics.hpp"
#include "participant.hpp"

namespace craneassist::dds {

// Wakes the thread that waits for samples; the listeners notify it from Fast DDS's threads.
class Wakeup {
 public:
  void notify();
  // Returns when notified (since the last wait) or after max_s seconds.
  void wait(double max_s);

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool pending_ = false;
};

// Called on a Fast DDS thread when a reader has data: take the samples there, or leave them to
// the waiting thread (the reader keeps the latest ones, KEEP_LAST).
using DataCallback = std::function<void(Topic, eprosima::fastdds::dds::DataReader&)>;

class TopicReader : public eprosima::fastdds::dds::DataReaderListener {
 public:
  TopicReader(Topic topic, Wakeup& wakeup, DataCallback on_data);

  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override;
  void on_subscription_matched(eprosima::fastdds::dds::DataReader* reader,
                               const eprosima::fastdds::dds::SubscriptionMatchedStatus& s) override;
  void on_requested_incompatible_qos(
      eprosima::fastdds::dds::DataReader* reader,
      const eprosima::fastdds::dds::RequestedIncompatibleQosStatus& s) override;

  Topic topic() const { return topic_; }
  eprosima::fastdds::dds::DataReader& reader() { return *reader_; }
  // Writers this reader matched. Fast DDS matches on its own side only: a writer of another DDS
  // implementation that rejects this reader's discovery data (for example Cyclone DDS and Fast
  // DDS 2.9's TYPE_INFORMATION) counts here and still never sends. Only a sample proves that
  // both sides matched.
  int matched_writers() const { return matched_.load(); }
  // CLOCK_MONOTONIC of the first match with a writer; 0 while none has matched.
  std::int64_t first_match_ns() const { return first_match_ns_.load(); }
  // Writers of the topic not matched because their QoS does not satisfy this reader's, and the
  // last policy at fault (a Fast DDS QosPolicyId_t), so far.
  int incompatible_writers() const { return incompatible_.load(); }
  std::uint32_t last_incompatible_policy() const { return last_policy_.load(); }

 private:
  friend class SubscriberSession;
  Topic topic_;
  Wakeup& wakeup_;
  DataCallback on_data_;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  std::atomic<int> matched_{0};
  std::atomic<std::int64_t> first_match_ns_{0};
  std::atomic<int> incompatible_{0};
  std::atomic<std::uint32_t> last_policy_{0};
};

class SubscriberSession {
 public:
  // Throws std::runtime_error when DDS cannot be set up. Each reader takes `reader_settings` of
  // its topic (default: best-effort and volatile, which match every writer).
  using ReaderSettings = std::function<config::TopicSettings(Topic)>;
  SubscriberSession(const ParticipantOptions& options, const std::vector<Topic>& topics,
                    DataCallback on_data = nullptr,
                    const ReaderSettings& reader_settings = default_reader_settings);
  ~SubscriberSession();
  SubscriberSession(const SubscriberSession&) = delete;
  SubscriberSession& operator=(const SubscriberSession&) = delete;

  TopicReader& reader(Topic topic);
  Wakeup& wakeup() { return wakeup_; }
  std::int64_t start_ns() const { return start_ns_; }
  double elapsed_s() const;

 private:
  Wakeup wakeup_;
  std::int64_t start_ns_ = 0;
  std::vector<std::unique_ptr<TopicReader>> readers_;
  ParticipantPtr participant_;  // declared last: deleted (with its readers) before the listeners
};

// The session of a tool (echo, dashboard): its participant `name` on the domain and transport
// and the readers of topics. nullptr when DDS cannot be set up, after saying why on err.
std::unique_ptr<SubscriberSession> open_tool_session(const std::string& name, int domain_id,
                                                     config::DdsTransport transport,
                                                     const config::TypePropagation& propagation,
                                                     const std::vector<Topic>& topics,
                                                     std::FILE* err,
                                                     DataCallback on_data = nullptr);

}  // namespace craneassist::dds
