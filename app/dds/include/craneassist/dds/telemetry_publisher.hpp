// Publishes the loop's telemetry frames on the DDS topics of config::TelemetryConfig.
//
// push() is the loop's side: it copies the frame into a preallocated single-producer/
// single-consumer ring and wakes the publisher thread (sem_post); no lock, no allocation, no
// I/O, never blocks. A full ring drops the frame and counts it. The publisher thread turns
// frames into samples and writes each topic at most at its configured rate (by machine time).
#pragma once

#include <cstdint>
#include <memory>

#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/dds/telemetry_frame.hpp"

namespace craneassist::dds {

struct PublisherStats {
  std::uint64_t frames_pushed = 0;
  std::uint64_t frames_dropped = 0;  // the ring was full (the publisher fell behind)
  // status, joints, hydraulics, command_path, base, fields
  std::uint64_t samples_written[6] = {};
  // The ROS 2 topics (config ros2): joint_states, tip velocity command, tip velocity reference.
  std::uint64_t ros2_samples_written[3] = {};
  std::uint64_t write_errors = 0;
  int matched_readers = 0;  // over all topics, at the time of the call
  // After close(): topics whose final sample (the end of the run) some reliable reader had not
  // acknowledged within the 0.5 s close() waits.
  int end_unacknowledged = 0;
};

class TelemetryPublisher {
 public:
  // Creates the participant, topics and writers; throws std::runtime_error when DDS cannot be
  // set up. capacity: frames in the ring.
  TelemetryPublisher(const config::TelemetryConfig& config, TelemetryInfo info,
                     std::size_t capacity = 1024);
  ~TelemetryPublisher();
  TelemetryPublisher(const TelemetryPublisher&) = delete;
  TelemetryPublisher& operator=(const TelemetryPublisher&) = delete;

  // Real-time safe (the loop thread). Stamps the frame and queues it; false when dropped.
  bool push(const TelemetryFrame& frame) noexcept;

  // Publishes what is queued (the latest sample of each topic, whatever its rate, so that the
  // final state is out) and stops the thread. Called by the destructor too.
  void close();

  PublisherStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// CLOCK_MONOTONIC in ns (the stamps of telemetry headers; comparable across processes).
std::int64_t monotonic_ns() noexcept;

}  // namespace craneassist::dds
