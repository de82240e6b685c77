// `craneassist echo TOPIC`: every sample of one topic, as text blocks (field names and SI units,
// like `ros2 topic echo`) or as CSV rows (one header line, then one row per sample).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fastdds/dds/core/policy/QosPolicies.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "checked_types.hpp"
#include "craneassist/dds/telemetry_publisher.hpp"
#include "craneassist/dds/tools.hpp"
#include "craneassist_msgs.h"
#include "joint_units.hpp"
#include "sample_views.hpp"
#include "subscriber.hpp"

namespace craneassist::dds {

namespace fdds = eprosima::fastdds::dds;
namespace msg = craneassist::msg;

namespace {

// What a sample holds, field by field: each message type describes itself once
// (describe(...) below) and the text and CSV writers render that description.
class FieldVisitor {
 public:
  virtual ~FieldVisitor() = default;
  virtual void begin_group(const char* name) = 0;
  virtual void end_group() = 0;
  virtual void integer(const char* name, long long value, const char* unit) = 0;
  virtual void number(const char* name, double value, const char* unit) = 0;
  virtual void text(const char* name, const std::string& value) = 0;
  virtual void flag(const char* name, bool value) = 0;
  virtual void vector3(const char* name, const std::array<double, 3>& v, const char* unit) = 0;
  // One value per joint; unit per joint (rad or m, rad/s or m/s, ...). The CSV writer names
  // the columns after the joints; the text writer prints the list.
  virtual void joints(const char* name, const std::vector<double>& values,
                      const std::vector<const char*>& units) = 0;
  // Per-joint lists that are not numbers (names, prismatic): text only (CSV column names).
  virtual void joint_names(const std::vector<std::string>& names) = 0;
  virtual void joint_flags(const char* name, const std::vector<bool>& flags) = 0;
};

void describe_header(const msg::Header& h, FieldVisitor& v) {
  v.begin_group("header");
  v.integer("cycle", static_cast<long long>(h.cycle()), "");
  v.number("t_s", h.t_s(), "s");
  v.integer("stamp_ns", static_cast<long long>(h.stamp_ns()), "ns");
  v.end_group();
}

void describe(const msg::Status& m, FieldVisitor& v) {
  describe_header(m.header(), v);
  v.text("crane", m.crane());
  v.text("backend", m.backend());
  v.text("status", m.state());  // the IDL's `state`; echo's name (and CSV column) is `status`
  v.text("stop_reason", m.stop_reason());
  v.text("active_limit", m.active_limit());
  v.text("pump_limit", m.pump_limit());
  v.text("input_source", m.input_source());
  v.flag("deadman", m.deadman());
  v.number("scale", m.scale(), "");
  v.number("tip_speed_m_s", m.tip_speed_m_s(), "m/s");
  v.number("tip_error_m", m.tip_error_m(), "m");
  v.number("loop_latency_max_s", m.loop_latency_max_s(), "s");
  v.number("loop_compute_s", m.loop_compute_s(), "s");
  v.number("loop_overruns", static_cast<double>(m.loop_overruns()), "");
  v.number("avail_speed_m_s", m.avail_speed_m_s(), "m/s");
  v.number("avail_speed_resolved_m_s", m.avail_speed_resolved_m_s(), "m/s");
  v.integer("polytope_dim", m.polytope_dim(), "");
  v.number("polytope_volume_m3_s3", m.polytope_volume_m3_s3(), "m^3/s^3");
  v.number("polytope_area_m2_s2", m.polytope_area_m2_s2(), "m^2/s^2");
  v.number("payload_estimate_kg", m.payload_estimate_kg(), "kg");
  v.flag("payload_converged", m.payload_converged());
  v.number("load_moment_ratio", m.load_moment_ratio(), "");
  v.number("rated_load_kg", m.rated_load_kg(), "kg");
  v.number("load_reach_m", m.load_reach_m(), "m");
  v.flag("load_warning", m.load_warning());
  v.flag("overload", m.overload());
  v.number("load_truth_kg", m.load_truth_kg(), "kg");
  v.number("swing_rad", m.swing_rad(), "rad");
  v.number("swing_radial_rad", m.swing_radial_rad(), "rad");
  v.number("swing_tangential_rad", m.swing_tangential_rad(), "rad");
}

void describe(const msg::JointState& m, FieldVisitor& v) {
  describe_header(m.header(), v);
  const std::size_t n = m.q().size();
  std::vector<const char*> position(n), rate(n), m_units(n, "m"), m_s(n, "m/s"), pa(n, "Pa"),
      none(n, "");
  for (std::size_t i = 0; i < n; ++i) {
    const bool p = is_prismatic(m, i);
    position[i] = p ? "m" : "rad";
    rate[i] = p ? "m/s" : "rad/s";
  }
  v.joint_names(m.names());
  v.joint_flags("prismatic", m.prismatic());
  v.joints("q", m.q(), position);
  v.joints("q_ref", m.q_ref(), position);
  v.joints("qdot", m.qdot(), rate);
  v.joints("cylinder_pos_m", m.cylinder_pos_m(), m_units);
  v.joints("cylinder_vel_m_s", m.cylinder_vel_m_s(), m_s);
  v.joints("load_pressure_pa", m.load_pressure_pa(), pa);
  v.joints("spool", m.spool(), none);
  v.vector3("tip_m", m.tip_m(), "m");
  v.vector3("tip_v_m_s", m.tip_v_m_s(), "m/s");
}

void describe(const msg::Hydraulics& m, FieldVisitor& v) {
  describe_header(m.header(), v);
  v.text("pump_mode", m.pump_mode());
  v.number("flow_m3_s", m.flow_m3_s(), "m^3/s");
  v.number("pressure_pa", m.pressure_pa(), "Pa");
  v.number("power_w", m.power_w(), "W");
  v.number("energy_j", m.energy_j(), "J");
  v.number("flow_limit_m3_s", m.flow_limit_m3_s(), "m^3/s");
  v.number("power_limit_w", m.power_limit_w(), "W");
  v.number("flow_demand_m3_s", m.flow_demand_m3_s(), "m^3/s");
  v.number("ref_power_w", m.ref_power_w(), "W");
  v.text("pump_limit", m.pump_limit());
}

void describe(const msg::CommandPath& m, FieldVisitor& v) {
  describe_header(m.header(), v);
  v.text("input_source", m.input_source());
  v.flag("deadman", m.deadman());
  v.vector3("command_m_s", m.command_m_s(), "m/s");
  v.vector3("reference_m_s", m.reference_m_s(), "m/s");
  v.number("scale", m.scale(), "");
  v.number("s", m.s(), "");
  v.number("sdot", m.sdot(), "1/s");
  v.number("sddot", m.sddot(), "1/s^2");
  v.number("sdddot", m.sdddot(), "1/s^3");
  v.number("sddot_min", m.sddot_min(), "1/s^2");
  v.number("sddot_max", m.sddot_max(), "1/s^2");
}

void describe(const msg::OperatorCommand& m, FieldVisitor& v) {
  v.integer("seq", static_cast<long long>(m.seq()), "");
  v.text("sender", m.sender());
  v.vector3("v_m_s", m.v_m_s(), "m/s");
  v.flag("deadman", m.deadman());
}

// The field table's values by name (craneassist/fields), each with its unit.
void describe(const msg::FieldValues& m, FieldVisitor& v) {
  describe_header(m.header(), v);
  const std::size_t n = std::min(m.names().size(), m.values().size());
  for (std::size_t i = 0; i < n; ++i) {
    v.number(m.names()[i].c_str(), m.values()[i], i < m.units().size() ? m.units()[i].c_str() : "");
  }
}

void describe(const msg::BaseState& m, FieldVisitor& v) {
  describe_header(m.header(), v);
  v.number("x_m", m.pose()[0], "m");
  v.number("y_m", m.pose()[1], "m");
  v.number("phi_rad", m.pose()[2], "rad");
  v.number("v_m_s", m.velocity()[0], "m/s");
  v.number("omega_rad_s", m.velocity()[1], "rad/s");
  v.number("v_cmd_m_s", m.command()[0], "m/s");
  v.number("omega_cmd_rad_s", m.command()[1], "rad/s");
  v.number("motor_flow_fl_m3_s", m.motor_flow_m3_s()[0], "m^3/s");
  v.number("motor_flow_fr_m3_s", m.motor_flow_m3_s()[1], "m^3/s");
  v.number("motor_flow_rl_m3_s", m.motor_flow_m3_s()[2], "m^3/s");
  v.number("motor_flow_rr_m3_s", m.motor_flow_m3_s()[3], "m^3/s");
  v.number("motor_flow_sum_m3_s", m.motor_flow_sum_m3_s(), "m^3/s");
  v.number("drive_max_flow_m3_s", m.drive_max_flow_m3_s(), "m^3/s");
  v.flag("shared_pump", m.shared_pump());
}

const char* qos_policy_name(std::uint32_t id) {
  switch (id) {
    case fdds::DURABILITY_QOS_POLICY_ID:
      return "durability";
    case fdds::DEADLINE_QOS_POLICY_ID:
      return "deadline";
    case fdds::OWNERSHIP_QOS_POLICY_ID:
      return "ownership";
    case fdds::LIVELINESS_QOS_POLICY_ID:
      return "liveliness";
    case fdds::RELIABILITY_QOS_POLICY_ID:
      return "reliability";
    case fdds::DESTINATIONORDER_QOS_POLICY_ID:
      return "destination order";
    case fdds::DATAREPRESENTATION_QOS_POLICY_ID:
      return "data representation";
    case fdds::TYPECONSISTENCYENFORCEMENT_QOS_POLICY_ID:
      return "type consistency";
    default:
      return "another policy";
  }
}

std::string format_number(const char* spec, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, spec, value);
  return buf;
}

// `name: value unit` lines, groups indented, lists in brackets; a sample ends with `---`.
class TextWriter : public FieldVisitor {
 public:
  explicit TextWriter(std::FILE* out) : out_(out) {}

  void begin_group(const char* name) override {
    line(name, "");
    indent_ += 2;
  }
  void end_group() override { indent_ -= 2; }
  void integer(const char* name, long long value, const char* unit) override {
    line(name, with_unit(std::to_string(value), unit));
  }
  void number(const char* name, double value, const char* unit) override {
    line(name, with_unit(format_number("%.6g", value), unit));
  }
  void text(const char* name, const std::string& value) override {
    line(name, value.empty() ? "\"\"" : value);
  }
  void flag(const char* name, bool value) override { line(name, value ? "true" : "false"); }
  void vector3(const char* name, const std::array<double, 3>& v, const char* unit) override {
    std::string s = "[";
    for (std::size_t i = 0; i < 3; ++i) {
      if (i > 0) s += ", ";
      s += format_number("%.6g", v[i]);
    }
    line(name, with_unit(s + "]", unit));
  }
  void joints(const char* name, const std::vector<double>& values,
              const std::vector<const char*>& units) override {
    // One unit for the whole list when every joint has the same; else one per value.
    bool same = true;
    for (std::size_t i = 1; i < units.size(); ++i) same = same && std::string(units[i]) == units[0];
    std::string s = "[";
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (i > 0) s += ", ";
      s += format_number("%.6g", values[i]);
      if (!same && i < units.size()) s = with_unit(s, units[i]);
    }
    s += "]";
    line(name, same && !units.empty() ? with_unit(s, units[0]) : s);
  }
  void joint_names(const std::vector<std::string>& names) override {
    std::string s = "[";
    for (std::size_t i = 0; i < names.size(); ++i) s += (i > 0 ? ", " : "") + names[i];
    line("names", s + "]");
  }
  void joint_flags(const char* name, const std::vector<bool>& flags) override {
    std::string s = "[";
    for (std::size_t i = 0; i < flags.size(); ++i) {
      s += std::string(i > 0 ? ", " : "") + (flags[i] ? "true" : "false");
    }
    line(name, s + "]");
  }

  template <typename T>
  void write(const T& sample) {
    describe(sample, *this);
    std::fputs("---\n", out_);
    std::fflush(out_);
  }

 private:
  static std::string with_unit(const std::string& value, const char* unit) {
    return unit[0] == '\0' ? value : value + " " + unit;
  }
  void line(const char* name, const std::string& value) {
    std::fprintf(out_, "%*s%s:%s%s\n", indent_, "", name, value.empty() ? "" : " ", value.c_str());
  }

  std::FILE* out_;
  int indent_ = 0;
};

// CSV: one column per scalar, x/y/z columns for vectors, one column per joint named after the
// joint (q_slew, ...). The header line is written with the first sample (the joint names come
// with it); a later sample with another joint count fills or cuts to the header's.
class CsvWriter : public FieldVisitor {
 public:
  explicit CsvWriter(std::FILE* out) : out_(out) {}

  void begin_group(const char* /*name*/) override {}
  void end_group() override {}
  void integer(const char* name, long long value, const char* /*unit*/) override {
    add(name, std::to_string(value));
  }
  void number(const char* name, double value, const char* /*unit*/) override {
    add(name, format_number("%.9g", value));
  }
  void text(const char* name, const std::string& value) override { add(name, quoted(value)); }
  void flag(const char* name, bool value) override { add(name, value ? "1" : "0"); }
  void vector3(const char* name, const std::array<double, 3>& v, const char* /*unit*/) override {
    static const char* const kAxis[3] = {"_x", "_y", "_z"};
    for (std::size_t i = 0; i < 3; ++i) {
      add(std::string(name) + kAxis[i], format_number("%.9g", v[i]));
    }
  }
  void joints(const char* name, const std::vector<double>& values,
              const std::vector<const char*>& /*units*/) override {
    // The header's column count for this field (its first sample's joint count).
    if (!header_written_) joint_counts_.push_back(values.size());
    const std::size_t n = joint_field_ < joint_counts_.size() ? joint_counts_[joint_field_] : 0;
    ++joint_field_;
    for (std::size_t i = 0; i < n; ++i) {
      add(std::string(name) + "_" + joint_column(i),
          i < values.size() ? format_number("%.9g", values[i]) : "");
    }
  }
  void joint_names(const std::vector<std::string>& names) override {
    if (!header_written_) names_ = names;
  }
  void joint_flags(const char* /*name*/, const std::vector<bool>& /*flags*/) override {}

  template <typename T>
  void write(const T& sample) {
    names_row_.clear();
    values_row_.clear();
    joint_field_ = 0;
    describe(sample, *this);
    if (!header_written_) {
      std::fputs(join(names_row_).c_str(), out_);
      header_written_ = true;
    }
    std::fputs(join(values_row_).c_str(), out_);
    std::fflush(out_);
  }

 private:
  void add(const std::string& name, const std::string& value) {
    if (!header_written_) names_row_.push_back(name);
    values_row_.push_back(value);
  }
  // The joint's name made a column-name suffix (letters, digits, _), or its index.
  std::string joint_column(std::size_t i) {
    if (i >= names_.size() || names_[i].empty()) return std::to_string(i);
    std::string s = names_[i];
    for (char& c : s) {
      const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
      if (!ok) c = '_';
    }
    return s;
  }
  static std::string quoted(const std::string& s) {
    if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
  }
  static std::string join(const std::vector<std::string>& cells) {
    std::string s;
    for (std::size_t i = 0; i < cells.size(); ++i) s += (i > 0 ? "," : "") + cells[i];
    return s + "\n";
  }

  std::FILE* out_;
  bool header_written_ = false;
  std::vector<std::size_t> joint_counts_;  // per joint field, in order
  std::size_t joint_field_ = 0;
  std::vector<std::string> names_;
  std::vector<std::string> names_row_, values_row_;
};

template <typename T>
int echo_topic(const TopicInfo& topic, const EchoOptions& o) {
  const auto session =
      open_tool_session("craneassist-echo", o.domain_id, o.transport, o.type_propagation,
                        std::vector<Topic>{topic.topic}, o.err);
  if (!session) return kToolRuntime;
  TopicReader& reader = session->reader(topic.topic);
  TextWriter text(o.out);
  CsvWriter csv(o.out);
  T sample;
  fdds::SampleInfo info;
  long printed = 0;
  const std::string name(topic.dds_name);
  auto plural = [](int n) { return n == 1 ? "" : "s"; };
  // One line when this reader first matches a writer, and one when the first sample arrives.
  // Fast DDS matches on this side alone: a writer can be matched here that does not match this
  // reader (another DDS implementation that rejects our discovery data) and never sends. Only
  // the first sample shows that samples flow.
  bool discovery_reported = false;
  auto report_discovery = [&] {
    if (discovery_reported || reader.first_match_ns() == 0) return;
    const int writers = reader.matched_writers();
    std::fprintf(o.err,
                 "craneassist echo: %s: discovered %d writer%s after %.2f s; waiting for a "
                 "sample\n",
                 name.c_str(), writers, plural(writers),
                 static_cast<double>(reader.first_match_ns() - session->start_ns()) * 1e-9);
    std::fflush(o.err);
    discovery_reported = true;
  };
  auto report_flow = [&] {
    if (printed != 0) return;
    const int writers = reader.matched_writers();
    std::fprintf(o.err,
                 "craneassist echo: %s: receiving, first sample after %.2f s (%d writer%s)\n",
                 name.c_str(), session->elapsed_s(), writers, plural(writers));
    std::fflush(o.err);
  };
  // Writers whose QoS cannot serve this reader (Fast DDS reports these; echo's best-effort,
  // volatile reader asks for little, so another implementation's writer is the likely one).
  int incompatible_reported = 0;
  auto report_incompatible = [&] {
    const int n = reader.incompatible_writers();
    if (n == incompatible_reported) return;
    std::fprintf(o.err, "craneassist echo: %s: %d writer%s not matched: incompatible QoS (%s)\n",
                 name.c_str(), n, plural(n), qos_policy_name(reader.last_incompatible_policy()));
    std::fflush(o.err);
    incompatible_reported = n;
  };
  // Samples that cannot be deserialized are dropped: said once when the first comes, and the
  // count when echo ends.
  std::uint64_t malformed = 0;
  bool malformed_reported = false;
  auto report_malformed = [&] {
    if (malformed == 0 || malformed_reported) return;
    std::fprintf(o.err,
                 "craneassist echo: %s: dropped a malformed sample (cannot be deserialized); "
                 "echo goes on\n",
                 std::string(topic.dds_name).c_str());
    std::fflush(o.err);
    malformed_reported = true;
  };
  struct ReportAtEnd {
    const EchoOptions& o;
    const TopicInfo& topic;
    const std::uint64_t& malformed;
    ~ReportAtEnd() {
      if (malformed == 0) return;
      std::fprintf(o.err, "craneassist echo: %s: %llu malformed samples dropped\n",
                   std::string(topic.dds_name).c_str(), static_cast<unsigned long long>(malformed));
      std::fflush(o.err);
    }
  } report_at_end{o, topic, malformed};
  while (!stop_requested()) {
    report_discovery();
    report_incompatible();
    while (!stop_requested() && take_next_valid(reader.reader(), &sample, info, malformed)) {
      report_malformed();
      report_discovery();
      report_flow();
      if (o.format == EchoFormat::kCsv) {
        csv.write(sample);
      } else {
        text.write(sample);
      }
      ++printed;
      if (o.count > 0 && printed >= o.count) return kToolOk;
    }
    report_malformed();
    double wait_s = 0.1;
    if (printed == 0 && o.timeout_s > 0.0) {
      const double left = o.timeout_s - session->elapsed_s();
      if (left <= 0.0) {
        const int writers = reader.matched_writers();
        std::string why;
        if (writers > 0) {
          why = " (" + std::to_string(writers) + " writer" + plural(writers) +
                " discovered, but no sample: silent, or another DDS implementation that does "
                "not match this reader, docs/telemetry.md#interoperability)";
        } else if (incompatible_reported > 0) {
          why = " (writers with incompatible QoS only)";
        }
        std::fprintf(o.err,
                     "craneassist: error: no sample on %s within %g s on domain %d%s; is "
                     "craneassist sim running with telemetry on?\n",
                     std::string(topic.dds_name).c_str(), o.timeout_s, o.domain_id, why.c_str());
        return kToolRuntime;
      }
      wait_s = std::min(wait_s, left);
    }
    session->wakeup().wait(wait_s);
  }
  return kToolOk;
}

template <typename T>
void echo_one(const T& sample, EchoFormat format, std::FILE* out) {
  if (format == EchoFormat::kCsv) {
    CsvWriter(out).write(sample);
  } else {
    TextWriter(out).write(sample);
  }
}

}  // namespace

void echo_sample(const msg::Status& sample, EchoFormat format, std::FILE* out) {
  echo_one(sample, format, out);
}
void echo_sample(const msg::JointState& sample, EchoFormat format, std::FILE* out) {
  echo_one(sample, format, out);
}
void echo_sample(const msg::Hydraulics& sample, EchoFormat format, std::FILE* out) {
  echo_one(sample, format, out);
}
void echo_sample(const msg::CommandPath& sample, EchoFormat format, std::FILE* out) {
  echo_one(sample, format, out);
}
void echo_sample(const msg::OperatorCommand& sample, EchoFormat format, std::FILE* out) {
  echo_one(sample, format, out);
}
void echo_sample(const msg::BaseState& sample, EchoFormat format, std::FILE* out) {
  echo_one(sample, format, out);
}
void echo_sample(const msg::FieldValues& sample, EchoFormat format, std::FILE* out) {
  echo_one(sample, format, out);
}

int run_echo(const EchoOptions& o) {
  const TopicInfo* topic = find_topic(o.topic);
  if (topic == nullptr) {
    std::fprintf(o.err, "craneassist: error: unknown topic '%s'; the topics: %s\n", o.topic.c_str(),
                 topic_names().c_str());
    return kToolUsage;
  }
  if (o.count < 0 || !(o.timeout_s >= 0.0)) {
    std::fprintf(o.err, "craneassist: error: --count and --timeout must not be negative\n");
    return kToolUsage;
  }
  switch (topic->topic) {
    case Topic::kStatus:
      return echo_topic<msg::Status>(*topic, o);
    case Topic::kJoints:
      return echo_topic<msg::JointState>(*topic, o);
    case Topic::kHydraulics:
      return echo_topic<msg::Hydraulics>(*topic, o);
    case Topic::kCommandPath:
      return echo_topic<msg::CommandPath>(*topic, o);
    case Topic::kOperatorCommand:
      return echo_topic<msg::OperatorCommand>(*topic, o);
    case Topic::kBase:
      return echo_topic<msg::BaseState>(*topic, o);
    case Topic::kFields:
      return echo_topic<msg::FieldValues>(*topic, o);
  }
  return kToolUsage;
}

}  // namespace craneassist::dds
