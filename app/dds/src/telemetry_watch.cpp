#include "craneassist/dds/telemetry_watch.hpp"

#include <algorithm>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <mutex>
#include <set>
#include <string_view>

#include "checked_types.hpp"
#include "craneassist/dds/telemetry_publisher.hpp"
#include "craneassist_msgs.h"
#include "subscriber.hpp"

namespace craneassist::dds {

namespace fdds = eprosima::fastdds::dds;
namespace msg = craneassist::msg;

namespace {

// A copy of `text` that is never freed (TelemetryFrame holds static strings). The texts are the
// names of a few enums; a peer that sends endless new ones gets "?" after the first 256.
const char* intern(const std::string& text) {
  static std::mutex mutex;
  static std::set<std::string, std::less<>> texts;
  std::lock_guard<std::mutex> lock(mutex);
  if (auto it = texts.find(text); it != texts.end()) return it->c_str();
  if (texts.size() >= 256) return "?";
  return texts.insert(text).first->c_str();
}

template <std::size_t N>
void copy_into(std::array<double, N>& to, const std::vector<double>& from, int n) {
  std::fill(to.begin(), to.end(), 0.0);
  std::copy_n(from.begin(), std::min<std::size_t>(from.size(), static_cast<std::size_t>(n)),
              to.begin());
}

}  // namespace

struct TelemetryWatch::Impl {
  explicit Impl(const WatchOptions& o) {
    ParticipantOptions po;
    po.domain_id = o.domain_id;
    po.name = o.participant_name;
    po.transport = o.transport;
    po.type_propagation = o.type_propagation;
    session = std::make_unique<SubscriberSession>(
        po,
        std::vector<Topic>{Topic::kStatus, Topic::kJoints, Topic::kHydraulics, Topic::kCommandPath,
                           Topic::kBase},
        [this](Topic topic, fdds::DataReader& reader) { take(topic, reader); },
        [status = o.status](Topic topic) {
          config::TopicSettings s = default_reader_settings(topic);
          if (topic == Topic::kStatus) {
            s.reliability = status.reliability;
            s.durability = status.durability;
          }
          return s;
        });
  }

  // On Fast DDS's threads (the samples are the caller's: two threads may take one topic).
  void take(Topic topic, fdds::DataReader& reader) {
    std::uint64_t bad = 0;
    switch (topic) {
      case Topic::kStatus:
        take_all<msg::Status>(reader, bad);
        break;
      case Topic::kJoints:
        take_all<msg::JointState>(reader, bad);
        break;
      case Topic::kHydraulics:
        take_all<msg::Hydraulics>(reader, bad);
        break;
      case Topic::kCommandPath:
        take_all<msg::CommandPath>(reader, bad);
        break;
      case Topic::kBase:
        take_all<msg::BaseState>(reader, bad);
        break;
      case Topic::kOperatorCommand:
      case Topic::kFields:
        break;
    }
    if (bad > 0) {
      std::lock_guard<std::mutex> lock(mutex);
      run.malformed += bad;
    }
  }

  template <typename Sample>
  void take_all(fdds::DataReader& reader, std::uint64_t& bad) {
    Sample sample;
    fdds::SampleInfo info;
    while (take_next_valid(reader, &sample, info, bad)) apply(sample);
  }

  void apply(const msg::Status& s) {
    std::lock_guard<std::mutex> lock(mutex);
    run.crane = s.crane();
    run.backend = s.backend();
    frame.status = intern(s.state());
    frame.stop_reason = intern(s.stop_reason());
    frame.active_limit = intern(s.active_limit());
    frame.pump_limit = intern(s.pump_limit());
    frame.input_source = intern(s.input_source());
    frame.deadman = s.deadman();
    frame.tip_error_m = s.tip_error_m();
    frame.loop_latency_max_s = s.loop_latency_max_s();
    frame.loop_compute_s = s.loop_compute_s();
    frame.loop_overruns = s.loop_overruns();
    frame.avail_speed_m_s = s.avail_speed_m_s();
    frame.avail_speed_resolved_m_s = s.avail_speed_resolved_m_s();
    frame.polytope_dim = s.polytope_dim();
    frame.polytope_volume_m3_s3 = s.polytope_volume_m3_s3();
    frame.polytope_area_m2_s2 = s.polytope_area_m2_s2();
    frame.payload_estimate_kg = s.payload_estimate_kg();
    frame.payload_converged = s.payload_converged();
    frame.load_moment_ratio = s.load_moment_ratio();
    frame.rated_load_kg = s.rated_load_kg();
    frame.load_reach_m = s.load_reach_m();
    frame.load_warning = s.load_warning();
    frame.load_overload = s.overload();
    frame.load_truth_kg = s.load_truth_kg();
    frame.swing_rad = s.swing_rad();
    frame.swing_radial_rad = s.swing_radial_rad();
    frame.swing_tangential_rad = s.swing_tangential_rad();
    updated();
  }

  void apply(const msg::JointState& j) {
    std::lock_guard<std::mutex> lock(mutex);
    frame.cycle = j.header().cycle();
    frame.t_s = j.header().t_s();
    frame.stamp_ns = j.header().stamp_ns();
    const int n = static_cast<int>(std::min<std::size_t>(j.q().size(), kMaxJoints));
    frame.dof = n;
    copy_into(frame.q, j.q(), n);
    copy_into(frame.q_ref, j.q_ref(), n);
    copy_into(frame.qdot, j.qdot(), n);
    copy_into(frame.cylinder_pos_m, j.cylinder_pos_m(), n);
    copy_into(frame.cylinder_vel_m_s, j.cylinder_vel_m_s(), n);
    copy_into(frame.load_pressure_pa, j.load_pressure_pa(), n);
    copy_into(frame.spool, j.spool(), n);
    frame.tip_m = j.tip_m();
    frame.tip_v_m_s = j.tip_v_m_s();
    run.joint_names = j.names();
    updated();
  }

  void apply(const msg::Hydraulics& h) {
    std::lock_guard<std::mutex> lock(mutex);
    frame.pump_flow_m3_s = h.flow_m3_s();
    frame.pump_pressure_pa = h.pressure_pa();
    frame.pump_power_w = h.power_w();
    frame.energy_j = h.energy_j();
    frame.flow_demand_m3_s = h.flow_demand_m3_s();
    frame.ref_power_w = h.ref_power_w();
    frame.pump_limit = intern(h.pump_limit());
    updated();
  }

  void apply(const msg::CommandPath& c) {
    std::lock_guard<std::mutex> lock(mutex);
    frame.command_m_s = c.command_m_s();
    frame.reference_m_s = c.reference_m_s();
    frame.scale = c.scale();
    frame.s = c.s();
    frame.sdot = c.sdot();
    frame.sddot = c.sddot();
    frame.sdddot = c.sdddot();
    frame.sddot_min = c.sddot_min();
    frame.sddot_max = c.sddot_max();
    frame.input_source = intern(c.input_source());
    frame.deadman = c.deadman();
    updated();
  }

  void apply(const msg::BaseState& b) {
    std::lock_guard<std::mutex> lock(mutex);
    frame.base_present = true;
    frame.base_shared_pump = b.shared_pump();
    frame.base_pose = b.pose();
    frame.base_velocity = b.velocity();
    frame.base_command = b.command();
    frame.base_motor_flow_m3_s = b.motor_flow_m3_s();
    frame.base_flow_sum_m3_s = b.motor_flow_sum_m3_s();
    frame.base_flow_max_m3_s = b.drive_max_flow_m3_s();
    base_ns = monotonic_ns();
    updated();
  }

  void updated() {
    ++seq;
    ++run.samples;
  }

  mutable std::mutex mutex;
  TelemetryFrame frame;
  WatchedRun run;
  std::uint64_t seq = 0;
  std::int64_t base_ns = 0;                    // when the latest base sample came (CLOCK_MONOTONIC)
  std::unique_ptr<SubscriberSession> session;  // last: its listeners stop before the rest goes
};

TelemetryWatch::TelemetryWatch(const WatchOptions& options)
    : impl_(std::make_unique<Impl>(options)) {}

TelemetryWatch::~TelemetryWatch() = default;

bool TelemetryWatch::latest(TelemetryFrame& out, std::uint64_t& seen) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (impl_->seq == seen) return false;
  // A run on a wheeled base sends its base with every frame (sim --drive): one that stopped
  // sending it for a second (another run, a fixed crane) stands on no base.
  if (impl_->frame.base_present && monotonic_ns() - impl_->base_ns > 1'000'000'000) {
    impl_->frame.base_present = false;
  }
  out = impl_->frame;
  seen = impl_->seq;
  return true;
}

WatchedRun TelemetryWatch::run() const {
  WatchedRun r;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    r = impl_->run;
  }
  for (Topic t : {Topic::kStatus, Topic::kJoints, Topic::kHydraulics, Topic::kCommandPath}) {
    r.writers += impl_->session->reader(t).matched_writers();
  }
  r.status_incompatible = impl_->session->reader(Topic::kStatus).incompatible_writers();
  return r;
}

}  // namespace craneassist::dds
