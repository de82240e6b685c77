#include "craneassist/dds/telemetry_publisher.hpp"

#include <semaphore.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/PublisherQos.hpp>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "craneassist_msgs.h"
#include "participant.hpp"
#include "ros2_writers.hpp"
#include "topic_pacer.hpp"

namespace craneassist::dds {

namespace fdds = eprosima::fastdds::dds;

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

namespace {

// status, joints, hydraulics, command_path, base (a run with a wheeled base only), fields
constexpr int kTelemetryTopics = 6;
constexpr int kBaseTopic = 4;
constexpr int kFieldsTopic = 5;
// How long the writers stay after the run's last samples when a best-effort topic has readers.
constexpr auto kBestEffortLinger = std::chrono::milliseconds(200);

template <typename Header>
void fill_header(Header& h, const TelemetryFrame& f) {
  h.cycle(f.cycle);
  h.t_s(f.t_s);
  h.stamp_ns(f.stamp_ns);
}

template <std::size_t N>
std::vector<double> first(const std::array<double, N>& a, int n) {
  return std::vector<double>(a.begin(), a.begin() + n);
}

}  // namespace

struct TelemetryPublisher::Impl {
  Impl(const config::TelemetryConfig& config, TelemetryInfo run_info, std::size_t capacity)
      : info(std::move(run_info)), base_settings(config.hydraulics), ring(capacity + 1) {
    const config::TopicSettings* settings[kTelemetryTopics] = {
        &config.status,     &config.joints, &config.hydraulics, &config.command_path,
        &config.hydraulics,  // the base at the hydraulics topic's rate and QoS
        &config.status};     // the fields at the status topic's
    for (int i = 0; i < kTelemetryTopics; ++i) pacers[i] = TopicPacer(settings[i]->rate_hz);
    participant = make_participant(participant_options(config));
    if (config.ros2.enabled) register_ros2_types(*participant, config.type_propagation);
    publisher = participant->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    if (publisher == nullptr) throw std::runtime_error("DDS: cannot create the publisher");
    const Topic topics[kTelemetryTopics] = {Topic::kStatus,      Topic::kJoints, Topic::kHydraulics,
                                            Topic::kCommandPath, Topic::kBase,   Topic::kFields};
    // The base's writer comes with the first frame that has a base (publish(), on the publisher
    // thread): a run without one offers no craneassist/base.
    for (int i = 0; i < kTelemetryTopics; ++i) {
      if (i == kBaseTopic) continue;
      writers[i] = publisher->create_datawriter(get_topic(*participant, topics[i]),
                                                writer_qos(*settings[i]));
      if (writers[i] == nullptr) {
        throw std::runtime_error("DDS: cannot create the writer of " +
                                 std::string(topic_info(topics[i]).dds_name));
      }
    }
    if (config.ros2.enabled) {
      ros2.emplace(*participant, *publisher, config.ros2, info);
    }
    joints.names(info.joint_names);
    fields.names(info.field_names);
    fields.units(info.field_units);
    joints.prismatic(info.joint_prismatic);
    sem_init(&wake, 0, 0);
    thread = std::thread([this] { run(); });
  }

  ~Impl() { close(); }

  bool push(const TelemetryFrame& frame) noexcept {
    const std::size_t h = head.load(std::memory_order_relaxed);
    const std::size_t next = (h + 1) % ring.size();
    pushed.fetch_add(1, std::memory_order_relaxed);
    if (next == tail.load(std::memory_order_acquire)) {
      dropped.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    ring[h] = frame;
    ring[h].stamp_ns = monotonic_ns();
    head.store(next, std::memory_order_release);
    sem_post(&wake);
    return true;
  }

  void close() {
    if (!thread.joinable()) return;
    stop.store(true);
    sem_post(&wake);
    thread.join();
    sem_destroy(&wake);
    for (auto*& w : writers) w = nullptr;
    base_writer.store(nullptr, std::memory_order_release);
    if (ros2) {
      for (int i = 0; i < Ros2Writers::kTopics; ++i) ros2_written[i] = ros2->written(i);
      ros2.reset();
    }
    participant.reset();
  }

  void run() {
    TelemetryFrame latest;
    bool have_latest = false;
    while (true) {
      timespec deadline{};
      clock_gettime(CLOCK_REALTIME, &deadline);
      deadline.tv_nsec += 100000000;
      if (deadline.tv_nsec >= 1000000000) {
        deadline.tv_sec += 1;
        deadline.tv_nsec -= 1000000000;
      }
      while (sem_timedwait(&wake, &deadline) != 0 && errno == EINTR) {
      }
      const bool stopping = stop.load();
      while (true) {
        const std::size_t t = tail.load(std::memory_order_relaxed);
        if (t == head.load(std::memory_order_acquire)) break;
        latest = ring[t];
        tail.store((t + 1) % ring.size(), std::memory_order_release);
        have_latest = true;
        publish(latest, false);
      }
      if (stopping) {
        if (have_latest) {
          publish(latest, true);  // the final state on every topic
          // The end of the run (status "stopped" and why) is on reliable topics: let the
          // matched readers have it before the writers go, for at most half a second (a reader
          // that died cannot hold the exit up).
          const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
          bool best_effort_matched = false;
          for (auto* w : writers) {
            const auto left_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                     until - std::chrono::steady_clock::now())
                                     .count();
            if (w == nullptr) continue;
            if (w->get_qos().reliability().kind == fdds::BEST_EFFORT_RELIABILITY_QOS) {
              fdds::PublicationMatchedStatus matched;
              best_effort_matched =
                  best_effort_matched ||
                  (w->get_publication_matched_status(matched) == ReturnCode_t::RETCODE_OK &&
                   matched.current_count > 0);
            }
            if (left_ns <= 0 || w->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(
                                    static_cast<std::int32_t>(left_ns / 1000000000),
                                    static_cast<std::uint32_t>(left_ns % 1000000000))) !=
                                    ReturnCode_t::RETCODE_OK) {
              end_unacknowledged.fetch_add(1, std::memory_order_relaxed);
            }
          }
          // A best-effort topic is never acknowledged, and a reader that has not yet taken its
          // last sample loses it when the writer goes (over shared memory, the sample's buffer
          // goes with the writer): its readers get a moment (kBestEffortLinger) to take it.
          if (best_effort_matched) {
            std::this_thread::sleep_until(
                std::min(until, std::chrono::steady_clock::now() + kBestEffortLinger));
          }
        }
        return;
      }
    }
  }

  // Writes each topic whose period has passed (by machine time); force: every topic not yet
  // written for this frame.
  void publish(const TelemetryFrame& f, bool force) {
    if (ros2 && !ros2->publish(f, force)) write_errors.fetch_add(1, std::memory_order_relaxed);
    for (int i = 0; i < kTelemetryTopics; ++i) {
      if (i == kBaseTopic && !f.base_present) continue;  // no base: nothing on craneassist/base
      if (!pacers[i].due(f, force)) continue;
      if (i == kBaseTopic && writers[i] == nullptr) {
        writers[i] = publisher->create_datawriter(get_topic(*participant, Topic::kBase),
                                                  writer_qos(base_settings));
        if (writers[i] == nullptr) {
          write_errors.fetch_add(1, std::memory_order_relaxed);
          continue;
        }
        base_writer.store(writers[i], std::memory_order_release);
      }
      bool ok = false;
      switch (i) {
        case 0:
          ok = write_status(f);
          break;
        case 1:
          ok = write_joints(f);
          break;
        case 2:
          ok = write_hydraulics(f);
          break;
        case 3:
          ok = write_command_path(f);
          break;
        case kFieldsTopic:
          ok = write_fields(f);
          break;
        default:
          ok = write_base(f);
          break;
      }
      if (ok) {
        written[i].fetch_add(1, std::memory_order_relaxed);
      } else {
        write_errors.fetch_add(1, std::memory_order_relaxed);
      }
    }
  }

  bool write_status(const TelemetryFrame& f) {
    fill_header(status.header(), f);
    status.crane(info.crane);
    status.backend(info.backend);
    status.state(f.status);
    status.stop_reason(f.stop_reason);
    status.active_limit(f.active_limit);
    status.pump_limit(f.pump_limit);
    status.input_source(f.input_source);
    status.deadman(f.deadman);
    status.scale(f.scale);
    status.tip_speed_m_s(std::sqrt(f.tip_v_m_s[0] * f.tip_v_m_s[0] +
                                   f.tip_v_m_s[1] * f.tip_v_m_s[1] +
                                   f.tip_v_m_s[2] * f.tip_v_m_s[2]));
    status.tip_error_m(f.tip_error_m);
    status.loop_latency_max_s(f.loop_latency_max_s);
    status.loop_compute_s(f.loop_compute_s);
    status.loop_overruns(f.loop_overruns);
    status.avail_speed_m_s(f.avail_speed_m_s);
    status.avail_speed_resolved_m_s(f.avail_speed_resolved_m_s);
    status.polytope_dim(static_cast<std::uint16_t>(std::clamp(f.polytope_dim, 0, 3)));
    status.polytope_volume_m3_s3(f.polytope_volume_m3_s3);
    status.polytope_area_m2_s2(f.polytope_area_m2_s2);
    status.payload_estimate_kg(f.payload_estimate_kg);
    status.payload_converged(f.payload_converged);
    status.load_moment_ratio(f.load_moment_ratio);
    status.rated_load_kg(f.rated_load_kg);
    status.load_reach_m(f.load_reach_m);
    status.load_warning(f.load_warning);
    status.overload(f.load_overload);
    status.load_truth_kg(f.load_truth_kg);
    status.swing_rad(f.swing_rad);
    status.swing_radial_rad(f.swing_radial_rad);
    status.swing_tangential_rad(f.swing_tangential_rad);
    return writers[0]->write(&status);
  }

  bool write_joints(const TelemetryFrame& f) {
    fill_header(joints.header(), f);
    const int n = std::min(f.dof, kMaxJoints);
    joints.q(first(f.q, n));
    joints.q_ref(first(f.q_ref, n));
    joints.qdot(first(f.qdot, n));
    joints.cylinder_pos_m(first(f.cylinder_pos_m, n));
    joints.cylinder_vel_m_s(first(f.cylinder_vel_m_s, n));
    joints.load_pressure_pa(first(f.load_pressure_pa, n));
    joints.spool(first(f.spool, n));
    joints.tip_m(f.tip_m);
    joints.tip_v_m_s(f.tip_v_m_s);
    return writers[1]->write(&joints);
  }

  bool write_base(const TelemetryFrame& f) {
    fill_header(base.header(), f);
    base.pose(f.base_pose);
    base.velocity(f.base_velocity);
    base.command(f.base_command);
    base.motor_flow_m3_s(f.base_motor_flow_m3_s);
    base.motor_flow_sum_m3_s(f.base_flow_sum_m3_s);
    base.drive_max_flow_m3_s(f.base_flow_max_m3_s);
    base.shared_pump(f.base_shared_pump);
    return writers[kBaseTopic]->write(&base);
  }

  bool write_fields(const TelemetryFrame& f) {
    fill_header(fields.header(), f);
    const int n = std::clamp(f.value_count, 0, kMaxFieldValues);
    fields.values().assign(f.values.begin(), f.values.begin() + n);
    return writers[kFieldsTopic]->write(&fields);
  }

  bool write_hydraulics(const TelemetryFrame& f) {
    fill_header(hydraulics.header(), f);
    hydraulics.pump_mode(info.pump_mode);
    hydraulics.flow_m3_s(f.pump_flow_m3_s);
    hydraulics.pressure_pa(f.pump_pressure_pa);
    hydraulics.power_w(f.pump_power_w);
    hydraulics.energy_j(f.energy_j);
    hydraulics.flow_limit_m3_s(info.flow_limit_m3_s);
    hydraulics.power_limit_w(info.power_limit_w);
    hydraulics.flow_demand_m3_s(f.flow_demand_m3_s);
    hydraulics.ref_power_w(f.ref_power_w);
    hydraulics.pump_limit(f.pump_limit);
    return writers[2]->write(&hydraulics);
  }

  bool write_command_path(const TelemetryFrame& f) {
    fill_header(command_path.header(), f);
    command_path.input_source(f.input_source);
    command_path.deadman(f.deadman);
    command_path.command_m_s(f.command_m_s);
    command_path.reference_m_s(f.reference_m_s);
    command_path.scale(f.scale);
    command_path.s(f.s);
    command_path.sdot(f.sdot);
    command_path.sddot(f.sddot);
    command_path.sdddot(f.sdddot);
    command_path.sddot_min(f.sddot_min);
    command_path.sddot_max(f.sddot_max);
    return writers[3]->write(&command_path);
  }

  PublisherStats stats() const {
    PublisherStats s;
    s.frames_pushed = pushed.load();
    s.frames_dropped = dropped.load();
    for (int i = 0; i < kTelemetryTopics; ++i) {
      s.samples_written[i] = written[i].load();
      fdds::PublicationMatchedStatus m;
      fdds::DataWriter* w =
          i == kBaseTopic ? base_writer.load(std::memory_order_acquire) : writers[i];
      if (w != nullptr && w->get_publication_matched_status(m) == ReturnCode_t::RETCODE_OK) {
        s.matched_readers += m.current_count;
      }
    }
    for (int i = 0; i < Ros2Writers::kTopics; ++i) {
      s.ros2_samples_written[i] = ros2 ? ros2->written(i) : ros2_written[i];
    }
    if (ros2) s.matched_readers += ros2->matched_readers();
    s.write_errors = write_errors.load();
    s.end_unacknowledged = end_unacknowledged.load();
    return s;
  }

  TelemetryInfo info;
  ParticipantPtr participant;
  fdds::Publisher* publisher = nullptr;
  fdds::DataWriter* writers[kTelemetryTopics] = {};
  // The base topic's writer is created by the publishing thread on the first frame with a base;
  // stats() (another thread) reads it through this.
  std::atomic<fdds::DataWriter*> base_writer{nullptr};
  std::optional<Ros2Writers> ros2;                        // config ros2.enabled
  std::uint64_t ros2_written[Ros2Writers::kTopics] = {};  // its counts, after close()
  // Publisher thread only:
  TopicPacer pacers[kTelemetryTopics];
  craneassist::msg::Status status;
  craneassist::msg::JointState joints;
  craneassist::msg::Hydraulics hydraulics;
  craneassist::msg::CommandPath command_path;
  craneassist::msg::BaseState base;
  craneassist::msg::FieldValues fields;
  config::TopicSettings base_settings;  // the hydraulics topic's rate and QoS
  // The ring (loop thread produces, publisher thread consumes).
  std::vector<TelemetryFrame> ring;
  std::atomic<std::size_t> head{0}, tail{0};
  sem_t wake{};
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> pushed{0}, dropped{0}, write_errors{0};
  std::atomic<std::uint64_t> written[kTelemetryTopics] = {};
  std::atomic<int> end_unacknowledged{0};
  std::thread thread;
};

TelemetryPublisher::TelemetryPublisher(const config::TelemetryConfig& config, TelemetryInfo info,
                                       std::size_t capacity)
    : impl_(std::make_unique<Impl>(config, std::move(info), capacity)) {}

TelemetryPublisher::~TelemetryPublisher() = default;

bool TelemetryPublisher::push(const TelemetryFrame& frame) noexcept {
  return impl_->push(frame);
}

void TelemetryPublisher::close() {
  impl_->close();
}

PublisherStats TelemetryPublisher::stats() const {
  return impl_->stats();
}

}  // namespace craneassist::dds
