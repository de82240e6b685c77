#include "craneassist/dds/command_writer.hpp"

#include <atomic>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/PublisherQos.hpp>
#include <stdexcept>

#include "command_participant.hpp"
#include "craneassist/input/command_source.hpp"
#include "craneassist_msgs.h"
#include "participant.hpp"

namespace craneassist::dds {

namespace fdds = eprosima::fastdds::dds;

struct CommandWriter::Impl : public fdds::DataWriterListener {
  explicit Impl(const CommandWriterOptions& options) : start_s(input::steady_now_s()) {
    if (options.insecure && !options.security.empty()) {
      throw std::invalid_argument("insecure: DDS Security files given too");
    }
    if (!options.insecure) {
      if (const std::string missing = missing_security_files(options.security); !missing.empty()) {
        throw std::invalid_argument("the operator's DDS Security identity is incomplete: " +
                                    missing);
      }
    }
    ParticipantOptions p;
    p.domain_id = options.domain_id;
    p.name = options.participant_name;
    p.transport = options.transport;
    p.type_propagation = options.type_propagation;
    p.security = options.security;
    participant = make_participant(p);
    fdds::Publisher* publisher = participant->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    if (publisher == nullptr) throw std::runtime_error("DDS: cannot create the publisher");
    writer = publisher->create_datawriter(get_topic(*participant, Topic::kOperatorCommand),
                                          writer_qos(options.topic), this,
                                          fdds::StatusMask::publication_matched());
    if (writer == nullptr) {
      throw std::runtime_error(
          options.insecure
              ? "DDS: cannot create the writer of craneassist/operator_command"
              : "DDS Security: cannot create the writer of craneassist/operator_command: this "
                "identity's permissions do not allow publishing it (Fast DDS logs the reason "
                "above)");
    }
    sample.sender(options.sender);
  }

  ~Impl() override { participant.reset(); }

  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  void on_publication_matched(fdds::DataWriter*, const fdds::PublicationMatchedStatus& s) override {
    if (s.current_count > 0 && first_match_s.load() < 0.0) {
      first_match_s.store(input::steady_now_s() - start_s);
    }
    if (s.current_count > peak_matched.load()) peak_matched.store(s.current_count);
    matched.store(s.current_count);
  }

  bool write(const std::array<double, 3>& v, bool deadman) {
    sample.seq(sample.seq() + 1);
    sample.v_m_s(v);
    sample.deadman(deadman);
    if (writer->write(&sample)) {
      ++written;
      return true;
    }
    ++errors;
    return false;
  }

  const double start_s;
  craneassist::msg::OperatorCommand sample;
  std::uint64_t written = 0, errors = 0;
  std::atomic<int> matched{0}, peak_matched{0};
  std::atomic<double> first_match_s{-1.0};
  ParticipantPtr participant;
  fdds::DataWriter* writer = nullptr;
};

CommandWriter::CommandWriter(const CommandWriterOptions& options)
    : impl_(std::make_unique<Impl>(options)) {}

CommandWriter::~CommandWriter() = default;

bool CommandWriter::write(const std::array<double, 3>& v_m_s, bool deadman) {
  return impl_->write(v_m_s, deadman);
}

int CommandWriter::matched_readers() const {
  return impl_->matched.load();
}

CommandWriterStats CommandWriter::stats() const {
  CommandWriterStats s;
  s.samples_written = impl_->written;
  s.write_errors = impl_->errors;
  s.matched_readers = impl_->matched.load();
  s.peak_matched_readers = impl_->peak_matched.load();
  s.first_match_s = impl_->first_match_s.load();
  return s;
}

}  // namespace craneassist::dds
