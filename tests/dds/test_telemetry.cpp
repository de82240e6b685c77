// DDS telemetry on loopback: every topic round trips with every field, each topic keeps its
// configured rate, push() on the loop's side allocates nothing, and the discovery time and the
// end-to-end latency (loop hand-off to a subscriber's listener) are reported as figures.
//
// C++17 like the dds module (Debian's Fast CDR 1.0 headers do not compile as C++20). Each test
// uses its own DDS domain (100..109) so parallel ctest runs do not cross-talk.
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/SubscriberQos.hpp>
#include <mutex>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/dds/telemetry_publisher.hpp"
#include "craneassist/dds/telemetry_watch.hpp"
#include "craneassist/dds/topics.hpp"
#include "craneassist_msgs.h"
#include "dds_test_frames.hpp"
#include "participant.hpp"
#include "sample_views.hpp"

// Heap allocations counted per thread: the publisher thread allocates (sample sequences and
// strings) while the loop's thread pushes; only the pusher's count is asserted.
namespace {
thread_local long t_allocations = 0;
}
[[gnu::noinline]] void* operator new(std::size_t size) {
  ++t_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  ++t_allocations;
  return std::malloc(size == 0 ? 1 : size);
}
[[gnu::noinline]] void* operator new[](std::size_t size) {
  ++t_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  ++t_allocations;
  return std::malloc(size == 0 ? 1 : size);
}
// Every delete that pairs with the news above. Under ASan a library's nothrow new (Fast DDS's
// foonathan allocator) would otherwise be ASan's and its delete ours: a mismatch.
[[gnu::noinline]] void operator delete(void* p) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}

namespace {

using namespace craneassist;
namespace cdds = craneassist::dds;
namespace fdds = eprosima::fastdds::dds;

// Collects every sample of one topic with its arrival time (CLOCK_MONOTONIC).
template <typename T>
class Collector : public fdds::DataReaderListener {
 public:
  void on_data_available(fdds::DataReader* reader) override {
    T sample;
    fdds::SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const std::int64_t now = cdds::monotonic_ns();
      std::lock_guard<std::mutex> lock(mutex_);
      samples_.push_back(sample);
      arrival_ns_.push_back(now);
      cv_.notify_all();
    }
  }
  void on_subscription_matched(fdds::DataReader*,
                               const fdds::SubscriptionMatchedStatus& status) override {
    if (status.current_count > 0 && matched_ns_.load() == 0)
      matched_ns_.store(cdds::monotonic_ns());
  }
  bool wait_for(std::size_t n, double timeout_s) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                        [&] { return samples_.size() >= n; });
  }
  std::vector<T> samples() {
    std::lock_guard<std::mutex> lock(mutex_);
    return samples_;
  }
  std::vector<std::int64_t> arrivals() {
    std::lock_guard<std::mutex> lock(mutex_);
    return arrival_ns_;
  }
  std::int64_t matched_ns() const { return matched_ns_.load(); }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<T> samples_;
  std::vector<std::int64_t> arrival_ns_;
  std::atomic<std::int64_t> matched_ns_{0};
};

// A subscriber participant with one reader per telemetry topic.
struct Subscriber {
  explicit Subscriber(int domain) {
    cdds::ParticipantOptions o;
    o.domain_id = domain;
    o.name = "test-subscriber";
    participant = cdds::make_participant(o);
    sub = participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    add(cdds::Topic::kStatus, &status);
    add(cdds::Topic::kJoints, &joints);
    add(cdds::Topic::kHydraulics, &hydraulics);
    add(cdds::Topic::kCommandPath, &command_path);
  }
  ~Subscriber() { participant.reset(); }  // readers go before the listeners
  void add(cdds::Topic topic, fdds::DataReaderListener* listener) {
    auto* r =
        sub->create_datareader(cdds::get_topic(*participant, topic),
                               cdds::reader_qos(cdds::default_reader_settings(topic)), listener);
    ASSERT_NE(r, nullptr);
  }
  bool all_matched(double timeout_s) const {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
      if (status.matched_ns() && joints.matched_ns() && hydraulics.matched_ns() &&
          command_path.matched_ns()) {
        return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  }
  Collector<craneassist::msg::Status> status;
  Collector<craneassist::msg::JointState> joints;
  Collector<craneassist::msg::Hydraulics> hydraulics;
  Collector<craneassist::msg::CommandPath> command_path;
  cdds::ParticipantPtr participant;
  fdds::Subscriber* sub = nullptr;
};

// Discovery is done when both sides know each other: the readers matched the writers, and the
// writers the readers (a writer drops what it writes before it knows a volatile reader).
bool discovered(const Subscriber& sub, const cdds::TelemetryPublisher& pub, double timeout_s) {
  if (!sub.all_matched(timeout_s)) return false;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    if (pub.stats().matched_readers >= 4) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

config::TelemetryConfig settings(int domain) {
  config::TelemetryConfig c = config::default_telemetry_config();
  c.domain_id = domain;
  return c;
}

cdds::TelemetryInfo info() {
  cdds::TelemetryInfo i = craneassist::test::test_telemetry_info();
  i.crane = "test crane";
  i.flow_limit_m3_s = 325.0 / 60000.0;
  return i;
}

// The synthetic frame of cycle k (machine time k * 10 ms) with every numeric field distinct.
cdds::TelemetryFrame frame(std::uint64_t k) {
  cdds::TelemetryFrame f = craneassist::test::test_frame(k);
  f.t_s = 0.01 * static_cast<double>(k);
  for (std::size_t i = 0; i < 4; ++i) {
    const double b = static_cast<double>(i) + 0.001 * static_cast<double>(k);
    f.q[i] = 1.0 + b;
    f.q_ref[i] = 2.0 + b;
    f.qdot[i] = 3.0 + b;
    f.cylinder_pos_m[i] = 4.0 + b;
    f.cylinder_vel_m_s[i] = 5.0 + b;
    f.load_pressure_pa[i] = 6e6 + b;
    f.spool[i] = 0.1 * static_cast<double>(i);
  }
  f.tip_m = {7.0, 8.0, 9.0};
  f.tip_v_m_s = {0.3, 0.0, 0.4};
  f.command_m_s = {0.5, 0.6, 0.7};
  f.reference_m_s = {0.25, 0.3, 0.35};
  f.pump_flow_m3_s = 1e-3;
  f.pump_pressure_pa = 12e6;
  f.pump_power_w = 12e3;
  f.energy_j = 5e4;
  f.flow_demand_m3_s = 0.9e-3;
  f.ref_power_w = 11e3;
  f.scale = 0.5;
  f.s = 1.5;
  f.sdot = 0.6;
  f.sddot = 0.1;
  f.sdddot = -2.0;
  f.sddot_min = -1.0;
  f.sddot_max = 0.8;
  f.tip_error_m = 0.004;
  f.input_source = "keyboard";
  // A planar arm's polytope: flat, its measure the area.
  f.avail_speed_m_s = 1.5;
  f.avail_speed_resolved_m_s = 1.25;
  f.polytope_dim = 2;
  f.polytope_volume_m3_s3 = 0.0;
  f.polytope_area_m2_s2 = 3.5;
  f.load_truth_kg = 1200.0;
  f.payload_estimate_kg = 1198.25;
  f.payload_converged = true;
  f.load_moment_ratio = 1.375;
  f.rated_load_kg = 871.5;
  f.load_reach_m = 5.25;
  f.load_warning = true;
  f.load_overload = true;
  return f;
}

TEST(Telemetry, EveryTopicRoundTripsEveryField) {
  Subscriber sub(100);
  cdds::TelemetryPublisher pub(settings(100), info());
  ASSERT_TRUE(discovered(sub, pub, 5.0));
  // One frame per 10 ms of machine time for 0.2 s: every topic is due at its first frame.
  for (std::uint64_t k = 0; k < 20; ++k) {
    ASSERT_TRUE(pub.push(frame(k)));
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(sub.status.wait_for(1, 3.0));
  ASSERT_TRUE(sub.joints.wait_for(1, 3.0));
  ASSERT_TRUE(sub.hydraulics.wait_for(1, 3.0));
  ASSERT_TRUE(sub.command_path.wait_for(1, 3.0));
  const cdds::TelemetryFrame f0 = frame(0);

  const auto s = sub.status.samples().front();
  EXPECT_EQ(s.header().cycle(), 0u);
  EXPECT_EQ(s.header().t_s(), 0.0);
  EXPECT_GT(s.header().stamp_ns(), 0);
  EXPECT_EQ(s.crane(), "test crane");
  EXPECT_EQ(s.backend(), "sim");
  EXPECT_EQ(s.state(), "running");
  EXPECT_EQ(s.stop_reason(), "");
  EXPECT_EQ(s.active_limit(), "power");
  EXPECT_EQ(s.pump_limit(), "none");
  EXPECT_EQ(s.input_source(), "keyboard");
  EXPECT_TRUE(s.deadman());
  EXPECT_EQ(s.scale(), 0.5);
  EXPECT_DOUBLE_EQ(s.tip_speed_m_s(), 0.5);
  EXPECT_EQ(s.tip_error_m(), 0.004);
  EXPECT_EQ(s.loop_latency_max_s(), 120e-6);
  EXPECT_EQ(s.loop_compute_s(), 40e-6);
  EXPECT_EQ(s.loop_overruns(), 2u);
  EXPECT_EQ(s.avail_speed_m_s(), 1.5);
  EXPECT_EQ(s.avail_speed_resolved_m_s(), 1.25);
  EXPECT_EQ(s.polytope_dim(), 2u);
  EXPECT_EQ(s.polytope_volume_m3_s3(), 0.0);
  EXPECT_EQ(s.polytope_area_m2_s2(), 3.5);
  EXPECT_EQ(s.payload_estimate_kg(), 1198.25);
  EXPECT_TRUE(s.payload_converged());
  EXPECT_EQ(s.load_moment_ratio(), 1.375);
  EXPECT_EQ(s.rated_load_kg(), 871.5);
  EXPECT_EQ(s.load_reach_m(), 5.25);
  EXPECT_TRUE(s.load_warning());
  EXPECT_TRUE(s.overload());
  EXPECT_EQ(s.load_truth_kg(), 1200.0);

  const auto j = sub.joints.samples().front();
  EXPECT_EQ(j.header().cycle(), 0u);
  ASSERT_EQ(j.names().size(), 4u);
  EXPECT_EQ(j.names()[3], "extension");
  ASSERT_EQ(j.prismatic().size(), 4u);
  EXPECT_FALSE(j.prismatic()[0]);
  EXPECT_TRUE(j.prismatic()[3]);
  ASSERT_EQ(j.q().size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(j.q()[i], f0.q[i]);
    EXPECT_EQ(j.q_ref()[i], f0.q_ref[i]);
    EXPECT_EQ(j.qdot()[i], f0.qdot[i]);
    EXPECT_EQ(j.cylinder_pos_m()[i], f0.cylinder_pos_m[i]);
    EXPECT_EQ(j.cylinder_vel_m_s()[i], f0.cylinder_vel_m_s[i]);
    EXPECT_EQ(j.load_pressure_pa()[i], f0.load_pressure_pa[i]);
    EXPECT_EQ(j.spool()[i], f0.spool[i]);
  }
  EXPECT_EQ(j.tip_m()[2], 9.0);
  EXPECT_EQ(j.tip_v_m_s()[2], 0.4);

  const auto h = sub.hydraulics.samples().front();
  EXPECT_EQ(h.pump_mode(), "load-sensing");
  EXPECT_EQ(h.flow_m3_s(), 1e-3);
  EXPECT_EQ(h.pressure_pa(), 12e6);
  EXPECT_EQ(h.power_w(), 12e3);
  EXPECT_EQ(h.energy_j(), 5e4);
  EXPECT_EQ(h.flow_limit_m3_s(), 325.0 / 60000.0);
  EXPECT_EQ(h.power_limit_w(), 35e3);
  EXPECT_EQ(h.flow_demand_m3_s(), 0.9e-3);
  EXPECT_EQ(h.ref_power_w(), 11e3);
  EXPECT_EQ(h.pump_limit(), "none");

  const auto c = sub.command_path.samples().front();
  EXPECT_EQ(c.input_source(), "keyboard");
  EXPECT_TRUE(c.deadman());
  EXPECT_EQ(c.command_m_s()[1], 0.6);
  EXPECT_EQ(c.reference_m_s()[2], 0.35);
  EXPECT_EQ(c.scale(), 0.5);
  EXPECT_EQ(c.s(), 1.5);
  EXPECT_EQ(c.sdot(), 0.6);
  EXPECT_EQ(c.sddot(), 0.1);
  EXPECT_EQ(c.sdddot(), -2.0);
  EXPECT_EQ(c.sddot_min(), -1.0);
  EXPECT_EQ(c.sddot_max(), 0.8);
  pub.close();
  EXPECT_EQ(pub.stats().frames_dropped, 0u);
}

// The wheeled base (sim --drive): craneassist/base carries its pose, motion, drive command and
// hub-motor flows, and only frames that have a base are published on it.
TEST(Telemetry, TheBaseTopicCarriesTheBaseOnlyWhenThereIsOne) {
  Subscriber sub(108);
  Collector<craneassist::msg::BaseState> base;
  sub.add(cdds::Topic::kBase, &base);
  cdds::TelemetryPublisher pub(settings(108), info());
  ASSERT_TRUE(discovered(sub, pub, 5.0));
  for (std::uint64_t k = 0; k < 20; ++k) {  // no base
    ASSERT_TRUE(pub.push(frame(k)));
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(sub.hydraulics.wait_for(1, 3.0));
  EXPECT_EQ(pub.stats().samples_written[4], 0u);
  // With a base: the writer comes with the first such frame; pushed until the reader has one.
  for (std::uint64_t k = 20; k < 1000 && base.samples().empty(); ++k) {
    cdds::TelemetryFrame f = frame(k);
    f.base_present = true;
    f.base_shared_pump = true;
    f.base_pose = {1.5, -2.0, 0.25};
    f.base_velocity = {0.3, 0.05};
    f.base_command = {0.32, 0.06};
    f.base_motor_flow_m3_s = {2e-4, 2.5e-4, 2.1e-4, 2.6e-4};
    f.base_flow_sum_m3_s = 9.2e-4;
    f.base_flow_max_m3_s = 1.05e-3;
    ASSERT_TRUE(pub.push(f));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_FALSE(base.samples().empty());
  const auto b = base.samples().back();
  EXPECT_GE(b.header().cycle(), 20u);
  EXPECT_EQ(b.pose()[0], 1.5);
  EXPECT_EQ(b.pose()[1], -2.0);
  EXPECT_EQ(b.pose()[2], 0.25);
  EXPECT_EQ(b.velocity()[1], 0.05);
  EXPECT_EQ(b.command()[0], 0.32);
  EXPECT_EQ(b.motor_flow_m3_s()[3], 2.6e-4);
  EXPECT_EQ(b.motor_flow_sum_m3_s(), 9.2e-4);
  EXPECT_EQ(b.drive_max_flow_m3_s(), 1.05e-3);
  EXPECT_TRUE(b.shared_pump());
  pub.close();
  EXPECT_GT(pub.stats().samples_written[4], 0u);
}

// `craneassist web`'s side: the four topics of a publisher, assembled again into the frame the
// loop pushed (the last one, which close() publishes on every topic), every field.
TEST(Telemetry, TheWatchAssemblesThePublishedFrame) {
  cdds::TelemetryWatch watch(cdds::WatchOptions{109, {}, {}, "watch"});
  cdds::TelemetryPublisher pub(settings(109), info());
  // Matched on both sides (best-effort samples before that are lost).
  for (int i = 0; i < 500 && (watch.run().writers < 4 || pub.stats().matched_readers < 4); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(watch.run().writers, 4);
  ASSERT_EQ(pub.stats().matched_readers, 4);
  for (std::uint64_t k = 0; k < 20; ++k) ASSERT_TRUE(pub.push(frame(k)));
  pub.close();
  cdds::TelemetryFrame got;
  const cdds::TelemetryFrame want = frame(19);
  std::uint64_t seen = 0;
  for (int i = 0; i < 300 && !(got.cycle == 19 && std::string(got.status) == "running" &&
                               got.pump_flow_m3_s == want.pump_flow_m3_s && got.sdot != 0.0);
       ++i) {
    watch.latest(got, seen);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(got.cycle, 19u);
  EXPECT_EQ(got.t_s, want.t_s);
  EXPECT_GT(got.stamp_ns, 0);
  ASSERT_EQ(got.dof, 4);
  // Whole arrays: the 4 joints, and zeros past them on both sides.
  for (auto field :
       {&cdds::TelemetryFrame::q, &cdds::TelemetryFrame::q_ref, &cdds::TelemetryFrame::qdot,
        &cdds::TelemetryFrame::cylinder_pos_m, &cdds::TelemetryFrame::cylinder_vel_m_s,
        &cdds::TelemetryFrame::load_pressure_pa, &cdds::TelemetryFrame::spool}) {
    EXPECT_EQ(got.*field, want.*field);
  }
  for (auto field : {&cdds::TelemetryFrame::tip_m, &cdds::TelemetryFrame::tip_v_m_s,
                     &cdds::TelemetryFrame::command_m_s, &cdds::TelemetryFrame::reference_m_s}) {
    EXPECT_EQ(got.*field, want.*field);
  }
  EXPECT_EQ(got.pump_flow_m3_s, want.pump_flow_m3_s);
  EXPECT_EQ(got.pump_pressure_pa, want.pump_pressure_pa);
  EXPECT_EQ(got.pump_power_w, want.pump_power_w);
  EXPECT_EQ(got.energy_j, want.energy_j);
  EXPECT_EQ(got.flow_demand_m3_s, want.flow_demand_m3_s);
  EXPECT_EQ(got.ref_power_w, want.ref_power_w);
  EXPECT_EQ(got.scale, want.scale);
  EXPECT_EQ(got.s, want.s);
  EXPECT_EQ(got.sdot, want.sdot);
  EXPECT_EQ(got.sddot, want.sddot);
  EXPECT_EQ(got.sdddot, want.sdddot);
  EXPECT_EQ(got.sddot_min, want.sddot_min);
  EXPECT_EQ(got.sddot_max, want.sddot_max);
  EXPECT_EQ(got.tip_error_m, want.tip_error_m);
  EXPECT_STREQ(got.status, want.status);
  EXPECT_STREQ(got.stop_reason, want.stop_reason);
  EXPECT_STREQ(got.active_limit, want.active_limit);
  EXPECT_STREQ(got.pump_limit, want.pump_limit);
  EXPECT_STREQ(got.input_source, want.input_source);
  EXPECT_EQ(got.deadman, want.deadman);
  EXPECT_EQ(got.loop_latency_max_s, want.loop_latency_max_s);
  EXPECT_EQ(got.loop_compute_s, want.loop_compute_s);
  EXPECT_EQ(got.loop_overruns, want.loop_overruns);
  EXPECT_EQ(got.avail_speed_m_s, want.avail_speed_m_s);
  EXPECT_EQ(got.avail_speed_resolved_m_s, want.avail_speed_resolved_m_s);
  EXPECT_EQ(got.polytope_dim, want.polytope_dim);
  EXPECT_EQ(got.polytope_volume_m3_s3, want.polytope_volume_m3_s3);
  EXPECT_EQ(got.polytope_area_m2_s2, want.polytope_area_m2_s2);
  EXPECT_EQ(got.payload_estimate_kg, want.payload_estimate_kg);
  EXPECT_EQ(got.payload_converged, want.payload_converged);
  EXPECT_EQ(got.load_moment_ratio, want.load_moment_ratio);
  EXPECT_EQ(got.rated_load_kg, want.rated_load_kg);
  EXPECT_EQ(got.load_reach_m, want.load_reach_m);
  EXPECT_EQ(got.load_warning, want.load_warning);
  EXPECT_EQ(got.load_overload, want.load_overload);
  EXPECT_EQ(got.load_truth_kg, want.load_truth_kg);
  const cdds::WatchedRun run = watch.run();
  EXPECT_EQ(run.crane, "test crane");
  EXPECT_EQ(run.backend, "sim");
  EXPECT_EQ(run.joint_names, (std::vector<std::string>{"slew", "lift", "tilt", "extension"}));
  EXPECT_EQ(run.malformed, 0u);
}

// 2 s of machine time at 100 Hz: status at 10 Hz and the others at 50 Hz (the defaults), a
// rate set in the settings is honoured (joints at 25 Hz), and close() publishes the last frame
// on every topic.
TEST(Telemetry, TopicsKeepTheirRates) {
  Subscriber sub(101);
  config::TelemetryConfig c = settings(101);
  c.joints.rate_hz = 25.0;
  cdds::TelemetryPublisher pub(c, info());
  ASSERT_TRUE(discovered(sub, pub, 5.0));
  const std::uint64_t n = 200;
  for (std::uint64_t k = 0; k < n; ++k) {
    ASSERT_TRUE(pub.push(frame(k)));
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  pub.close();
  const auto stats = pub.stats();
  EXPECT_EQ(stats.frames_pushed, n);
  EXPECT_EQ(stats.frames_dropped, 0u);
  EXPECT_EQ(stats.write_errors, 0u);
  // 0, 0.1, ..., 1.9 s plus the final frame at 1.99 s.
  EXPECT_EQ(stats.samples_written[0], 21u);
  EXPECT_EQ(stats.samples_written[1], 51u);   // 25 Hz
  EXPECT_EQ(stats.samples_written[2], 101u);  // 50 Hz
  EXPECT_EQ(stats.samples_written[3], 101u);
  ASSERT_TRUE(sub.status.wait_for(21, 3.0));
  EXPECT_EQ(sub.status.samples().back().header().cycle(), n - 1);
  // Best effort on loopback: allow a lost sample, never more.
  EXPECT_TRUE(sub.joints.wait_for(50, 3.0));
  EXPECT_TRUE(sub.hydraulics.wait_for(100, 3.0));
  EXPECT_TRUE(sub.command_path.wait_for(100, 3.0));
}

// The loop's side: push() copies into the preallocated ring; no heap allocation on the pushing
// thread, also when the ring is full and frames are dropped.
TEST(Telemetry, PushDoesNotAllocate) {
  cdds::TelemetryPublisher pub(settings(102), info(), 8);
  cdds::TelemetryFrame f = frame(1);
  const long before = t_allocations;
  int accepted = 0;
  for (std::uint64_t k = 0; k < 2000; ++k) {
    f.cycle = k;
    f.t_s = 0.01 * static_cast<double>(k);
    accepted += pub.push(f);
  }
  const long allocations = t_allocations - before;
  pub.close();
  EXPECT_EQ(allocations, 0);
  const auto stats = pub.stats();
  EXPECT_EQ(stats.frames_pushed, 2000u);
  EXPECT_EQ(stats.frames_dropped, 2000u - static_cast<std::uint64_t>(accepted));
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1));
  return v[i];
}

// Prints the latency from each joint sample's stamp (the publisher's hand-off) to its arrival.
void report_latency(Collector<craneassist::msg::JointState>& joints) {
  const auto samples = joints.samples();
  const auto arrivals = joints.arrivals();
  std::vector<double> latency_us;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    latency_us.push_back(static_cast<double>(arrivals[i] - samples[i].header().stamp_ns()) * 1e-3);
  }
  ASSERT_FALSE(latency_us.empty());
  std::printf(
      "latency push -> listener over %zu joint samples: median %.0f us, p99 %.0f us, max %.0f "
      "us\n",
      latency_us.size(), percentile(latency_us, 0.5), percentile(latency_us, 0.99),
      percentile(latency_us, 1.0));
  EXPECT_GT(percentile(latency_us, 0.5), 0.0);
}

// Figures: discovery time (publisher created to every reader matched) and end-to-end latency
// from the loop's hand-off (push) to the subscriber's listener, 3 s at 100 Hz paced in real
// time, over the default transports (shared memory between processes on one host; in one
// process Fast DDS uses intraprocess delivery). Only sanity is asserted: timing is reported,
// not tested.
TEST(Telemetry, DiscoveryAndLatencyFigures) {
  Subscriber sub(103);
  const std::int64_t t0 = cdds::monotonic_ns();
  cdds::TelemetryPublisher pub(settings(103), info());
  ASSERT_TRUE(discovered(sub, pub, 5.0));
  const std::int64_t matched = cdds::monotonic_ns();  // both sides matched
  auto next = std::chrono::steady_clock::now();
  for (std::uint64_t k = 0; k < 300; ++k) {
    pub.push(frame(k));
    next += std::chrono::milliseconds(10);
    std::this_thread::sleep_until(next);
  }
  pub.close();
  ASSERT_TRUE(sub.joints.wait_for(140, 3.0));
  std::printf(
      "[ figures  ] discovery (publisher created -> its 4 writers and the 4 readers matched): %.1f "
      "ms; ",
      static_cast<double>(matched - t0) * 1e-6);
  report_latency(sub.joints);
}

// The same figures between two processes, as a dashboard sees them: tests/dds_test_publisher
// (a fresh process: no fork of one that has run DDS) publishes 4 s at 100 Hz paced in real time,
// this one subscribes; over the default transports (shared memory between processes of one
// host). What it publishes before discovery is done is not counted.
void cross_process_figures(int domain, const char* transport, const char* label) {
  Subscriber sub(domain);
  const std::int64_t t0 = cdds::monotonic_ns();
  const std::string domain_text = std::to_string(domain);
  char* const argv[] = {const_cast<char*>(DDS_TEST_PUBLISHER),
                        const_cast<char*>(domain_text.c_str()), const_cast<char*>("4"),
                        const_cast<char*>(transport), nullptr};
  pid_t child = -1;
  ASSERT_EQ(posix_spawn(&child, DDS_TEST_PUBLISHER, nullptr, nullptr, argv, environ), 0);
  const bool matched = sub.all_matched(10.0);
  const std::int64_t t_matched = cdds::monotonic_ns();
  const bool got = matched && sub.joints.wait_for(140, 8.0);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(matched);
  ASSERT_TRUE(got);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  std::printf(
      "[ figures  ] two processes, %s: readers matched %.1f ms after the publisher was "
      "started; ",
      label, static_cast<double>(t_matched - t0) * 1e-6);
  report_latency(sub.joints);
}

TEST(Telemetry, CrossProcessLatencyFiguresSharedMemory) {
  cross_process_figures(104, "default", "default transports (shared memory)");
}

// The dashboard's polytope lines (docs/dashboard.md), from the samples alone: the stick's speed
// (command_path) against the available speed along it (status), and the polytope's measure in
// the unit of its dimension.
TEST(Dashboard, ShowsTheStickAgainstTheAvailableSpeedAndThePolytopeMeasure) {
  craneassist::msg::Status status;
  status.avail_speed_m_s(1.25);
  status.avail_speed_resolved_m_s(1.0);
  status.polytope_dim(3);
  status.polytope_volume_m3_s3(51.51);
  craneassist::msg::CommandPath path;
  path.command_m_s({0.3, 0.4, 0.0});
  auto shows = [&](std::initializer_list<const char*> texts) {
    const auto lines = cdds::dashboard_view(&status, nullptr, nullptr, &path);
    std::string all;
    for (const auto& line : lines) all += line + "\n";
    for (const char* text : texts) {
      EXPECT_NE(all.find(text), std::string::npos) << "missing: " << text << "\n" << all;
    }
  };
  shows({"stick     [############..................]  0.50 /  1.25 m/s available   40 %",
         "polytope  volume 51.51 m^3/s^3        along the chosen joint motion 1.00 m/s"});
  // A planar arm (or a singular pose): flat, its area; a segment has neither.
  status.polytope_dim(2);
  status.polytope_volume_m3_s3(0.0);
  status.polytope_area_m2_s2(3.5);
  shows({"polytope  area 3.5 m^2/s^2 (flat)"});
  status.polytope_dim(1);
  status.polytope_area_m2_s2(0.0);
  shows({"polytope  dimension 1: no motion across it"});
  // Asking for more than there is: the bar full, the share above 100 %.
  path.command_m_s({2.0, 0.0, 0.0});
  shows({"stick     [##############################]  2.00 /  1.25 m/s available  160 %"});
  // No valid operator input (NaN command): no stick speed.
  path.command_m_s({NAN, NAN, NAN});
  shows({"stick     [..............................]     - /  1.25 m/s available"});
  // No status yet.
  const auto lines = cdds::dashboard_view(nullptr, nullptr, nullptr, &path);
  EXPECT_NE(std::find(lines.begin(), lines.end(), "stick     -"), lines.end());
  EXPECT_NE(std::find(lines.begin(), lines.end(), "polytope  -"), lines.end());
}

// The load's lines (docs/loads.md): the crane scale's estimate, whether it has weighed the load,
// the reach and the simulated truth; the load moment against the chart, its warning and trip.
TEST(Dashboard, ShowsTheCraneScaleAndTheLoadMoment) {
  craneassist::msg::Status status;
  status.payload_estimate_kg(1198.25);
  status.payload_converged(true);
  status.load_moment_ratio(1.375);
  status.rated_load_kg(871.5);
  status.load_reach_m(5.25);
  status.load_warning(true);
  status.overload(true);
  status.load_truth_kg(1200.0);
  auto all = [&] {
    std::string text;
    for (const auto& line : cdds::dashboard_view(&status, nullptr, nullptr, nullptr)) {
      text += line + "\n";
    }
    return text;
  };
  std::string text = all();
  for (const char* want :
       {"scale      1198.2 kg weighed                  at 5.25 m reach  (simulated 1200 kg)",
        "moment    [##############################]  138 % of 872 kg rated  OVERLOAD"}) {
    EXPECT_NE(text.find(want), std::string::npos) << "missing: " << want << "\n" << text;
  }
  // Not yet weighed, on a machine (no truth), under the warning: no flags.
  status.payload_converged(false);
  status.load_truth_kg(NAN);
  status.load_moment_ratio(0.5);
  status.load_warning(false);
  status.overload(false);
  text = all();
  EXPECT_NE(text.find("weighing (rated assumed) at 5.25 m reach\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("simulated"), std::string::npos) << text;
  EXPECT_EQ(text.find("WARNING"), std::string::npos) << text;
  // No chart: no gauge.
  status.rated_load_kg(0.0);
  EXPECT_NE(all().find("moment    no load chart"), std::string::npos);
}

// The wheeled base's lines (sim --drive): only when the base topic has a sample.
TEST(Dashboard, ShowsTheBaseWhenThereIsOne) {
  craneassist::msg::BaseState base;
  base.pose({12.5, -3.0, 0.4});
  base.velocity({0.3, 0.05});
  base.motor_flow_sum_m3_s(0.8e-3);
  base.drive_max_flow_m3_s(1.05e-3);
  base.shared_pump(true);
  std::string all;
  for (const auto& line : cdds::dashboard_view(nullptr, nullptr, nullptr, nullptr, &base)) {
    all += line + "\n";
  }
  for (const char* text :
       {"base      x  +12.500  y   -3.000 m  heading   22.9 deg   +0.30 m/s  +2.9 deg/s",
        "drive     [#######################.......]   48.0 /   63.0 L/min   76 %  hub motors "
        "(the crane shares the pump)"}) {
    EXPECT_NE(all.find(text), std::string::npos) << "missing: " << text << "\n" << all;
  }
  for (const auto& line : cdds::dashboard_view(nullptr, nullptr, nullptr, nullptr)) {
    EXPECT_NE(line.rfind("base", 0), 0u) << "a fixed crane has no base line: " << line;
  }
}

}  // namespace
