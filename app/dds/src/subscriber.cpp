#include "subscriber.hpp"

#include <chrono>
#include <fastdds/dds/subscriber/qos/SubscriberQos.hpp>
#include <stdexcept>
#include <string>
#include <utility>

#include "craneassist/dds/telemetry_publisher.hpp"
#include "craneassist/dds/tools.hpp"

namespace craneassist::dds {

namespace fdds = eprosima::fastdds::dds;

namespace {

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "request_stop() must be signal-safe");

}  // namespace

void request_stop() noexcept {
  g_stop.store(true);
}
bool stop_requested() noexcept {
  return g_stop.load();
}
void reset_stop() noexcept {
  g_stop.store(false);
}

std::string topic_names() {
  std::string names;
  for (const auto& t : kTopics) {
    if (!names.empty()) names += ", ";
    names += t.short_name;
  }
  return names + " (or the DDS names, craneassist/status, ...)";
}

void Wakeup::notify() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = true;
  }
  cv_.notify_one();
}

void Wakeup::wait(double max_s) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (max_s > 0.0) {
    cv_.wait_for(lock, std::chrono::duration<double>(max_s), [this] { return pending_; });
  }
  pending_ = false;
}

TopicReader::TopicReader(Topic topic, Wakeup& wakeup, DataCallback on_data)
    : topic_(topic), wakeup_(wakeup), on_data_(std::move(on_data)) {}

void TopicReader::on_data_available(fdds::DataReader* reader) {
  if (on_data_ && reader != nullptr) on_data_(topic_, *reader);
  wakeup_.notify();
}

void TopicReader::on_subscription_matched(fdds::DataReader* /*reader*/,
                                          const fdds::SubscriptionMatchedStatus& s) {
  matched_.store(s.current_count);
  if (s.current_count > 0) {
    std::int64_t none = 0;
    first_match_ns_.compare_exchange_strong(none, monotonic_ns());
  }
  wakeup_.notify();
}

void TopicReader::on_requested_incompatible_qos(fdds::DataReader* /*reader*/,
                                                const fdds::RequestedIncompatibleQosStatus& s) {
  incompatible_.store(static_cast<int>(s.total_count));
  last_policy_.store(static_cast<std::uint32_t>(s.last_policy_id));
  wakeup_.notify();
}

SubscriberSession::SubscriberSession(const ParticipantOptions& options,
                                     const std::vector<Topic>& topics, DataCallback on_data,
                                     const ReaderSettings& reader_settings)
    : start_ns_(monotonic_ns()) {
  participant_ = make_participant(options);
  fdds::Subscriber* subscriber = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  if (subscriber == nullptr) throw std::runtime_error("DDS: cannot create the subscriber");
  for (Topic topic : topics) {
    auto r = std::make_unique<TopicReader>(topic, wakeup_, on_data);
    r->reader_ = subscriber->create_datareader(get_topic(*participant_, topic),
                                               reader_qos(reader_settings(topic)), r.get());
    if (r->reader_ == nullptr) {
      throw std::runtime_error("DDS: cannot create the reader of " +
                               std::string(topic_info(topic).dds_name));
    }
    readers_.push_back(std::move(r));
  }
}

SubscriberSession::~SubscriberSession() {
  // No callback into the listeners once they start to go away.
  for (auto& r : readers_) r->reader_->set_listener(nullptr);
  participant_.reset();
}

TopicReader& SubscriberSession::reader(Topic topic) {
  for (auto& r : readers_) {
    if (r->topic() == topic) return *r;
  }
  throw std::logic_error("SubscriberSession: no reader of " +
                         std::string(topic_info(topic).dds_name));
}

double SubscriberSession::elapsed_s() const {
  return static_cast<double>(monotonic_ns() - start_ns_) * 1e-9;
}

std::unique_ptr<SubscriberSession> open_tool_session(const std::string& name, int domain_id,
                                                     config::DdsTransport transport,
                                                     const config::TypePropagation& propagation,
                                                     const std::vector<Topic>& topics,
                                                     std::FILE* err, DataCallback on_data) {
  ParticipantOptions po;
  po.domain_id = domain_id;
  po.name = name;
  po.transport = transport;
  po.type_propagation = propagation;
  try {
    return std::make_unique<SubscriberSession>(po, topics, std::move(on_data));
  } catch (const std::exception& e) {
    std::fprintf(err, "craneassist: error: %s\n", e.what());
    return nullptr;
  }
}

}  // namespace craneassist::dds
