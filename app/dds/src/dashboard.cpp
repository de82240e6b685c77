// `craneassist dashboard`: the four telemetry topics in one terminal view, redrawn about ten
// times a second with plain ANSI sequences (cursor home, erase to end of line and of screen; no
// curses), or one plain snapshot (--once, or stdout not a terminal).
#include <poll.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <memory>
#include <mutex>
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

constexpr int kTelemetryTopics = 4;
constexpr Topic kTelemetry[kTelemetryTopics] = {Topic::kStatus, Topic::kJoints, Topic::kHydraulics,
                                                Topic::kCommandPath};
constexpr double kStaleS = 1.0;  // a topic whose latest sample is older shows STALE
constexpr double kPi = 3.14159265358979323846;

int index_of(Topic t) {
  for (int i = 0; i < kTelemetryTopics; ++i) {
    if (kTelemetry[i] == t) return i;
  }
  return -1;
}

// The latest sample of each telemetry topic and when it arrived.
struct Snapshot {
  msg::Status status;
  msg::JointState joints;
  msg::Hydraulics hydraulics;
  msg::CommandPath command_path;
  std::int64_t received_ns[kTelemetryTopics] = {};  // CLOCK_MONOTONIC; 0: nothing yet
  // The wheeled base (craneassist/base): only a crane on a base publishes it, so it is not one
  // of the topics the view waits for.
  msg::BaseState base;
  std::int64_t base_received_ns = 0;
  // Every value of the field table (craneassist/fields): the --fields view. Not waited for.
  msg::FieldValues fields;
  std::int64_t fields_received_ns = 0;
  int matched[kTelemetryTopics] = {};
  std::uint64_t malformed[kTelemetryTopics] = {};  // dropped: could not be deserialized

  bool has(Topic t) const { return received_ns[index_of(t)] != 0; }
  bool any() const {
    for (auto ns : received_ns) {
      if (ns != 0) return true;
    }
    return false;
  }
  bool all() const {
    for (auto ns : received_ns) {
      if (ns == 0) return false;
    }
    return true;
  }
};

// Filled on Fast DDS's threads (the readers' listeners): takes every sample and keeps the
// latest, so the view never misses the newest state however slowly it is drawn. Malformed
// samples are dropped and counted per topic.
class LatestSamples {
 public:
  void take(Topic topic, fdds::DataReader& reader) {
    switch (topic) {
      case Topic::kStatus:
        take_into<msg::Status>(reader, &Snapshot::status, topic);
        break;
      case Topic::kJoints:
        take_into<msg::JointState>(reader, &Snapshot::joints, topic);
        break;
      case Topic::kHydraulics:
        take_into<msg::Hydraulics>(reader, &Snapshot::hydraulics, topic);
        break;
      case Topic::kCommandPath:
        take_into<msg::CommandPath>(reader, &Snapshot::command_path, topic);
        break;
      case Topic::kBase:
        take_into<msg::BaseState>(reader, &Snapshot::base, topic);
        break;
      case Topic::kFields:
        take_into<msg::FieldValues>(reader, &Snapshot::fields, topic);
        break;
      case Topic::kOperatorCommand:
        break;
    }
  }

  Snapshot copy() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return latest_;
  }

 private:
  // The base (index -1: not one of the telemetry topics) has its own arrival time and no
  // malformed count.
  template <typename T>
  void take_into(fdds::DataReader& reader, T Snapshot::*field, Topic topic) {
    const int i = index_of(topic);
    T sample;
    fdds::SampleInfo info;
    std::uint64_t malformed = 0;
    while (take_next_valid(reader, &sample, info, malformed)) {
      std::lock_guard<std::mutex> lock(mutex_);
      latest_.*field = sample;
      (i >= 0                    ? latest_.received_ns[i]
       : topic == Topic::kFields ? latest_.fields_received_ns
                                 : latest_.base_received_ns) = monotonic_ns();
    }
    if (malformed > 0 && i >= 0) {
      std::lock_guard<std::mutex> lock(mutex_);
      latest_.malformed[i] += malformed;
    }
  }

  mutable std::mutex mutex_;
  Snapshot latest_;
};

__attribute__((format(printf, 1, 2))) std::string fmt(const char* format, ...) {
  char buf[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buf, sizeof buf, format, args);
  va_end(args);
  return buf;
}

std::string or_dash(const std::string& s) {
  return s.empty() ? "-" : s;
}

// The value as printed with `decimals` decimals, without "-0.0" for a tiny negative value.
double shown(double value, int decimals) {
  const double scale = std::pow(10.0, decimals);
  const double rounded = std::round(value * scale) / scale;
  return rounded == 0.0 ? 0.0 : rounded;
}

// "[#########...........]" for value against limit.
std::string bar(double value, double limit, int width) {
  const double fraction = limit > 0.0 ? std::clamp(value / limit, 0.0, 1.0) : 0.0;
  const int filled = static_cast<int>(std::lround(fraction * width));
  return "[" + std::string(static_cast<std::size_t>(filled), '#') +
         std::string(static_cast<std::size_t>(width - filled), '.') + "]";
}

std::string percent(double value, double limit) {
  return limit > 0.0 ? fmt("%3.0f %%", 100.0 * value / limit) : std::string("  - %");
}

std::string xyz(const std::array<double, 3>& v, const char* spec, const char* unit) {
  std::string s;
  const char* axis[3] = {"x ", "  y ", "  z "};
  for (std::size_t i = 0; i < 3; ++i) s += axis[i] + fmt(spec, shown(v[i], 3));
  return s + " " + unit;
}

double norm(const std::array<double, 3>& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

// The tip polytope's measure with its unit: a volume when it is a solid, an area when it is
// flat (a planar arm, a singular pose).
std::string polytope_measure(const msg::Status& m) {
  switch (m.polytope_dim()) {
    case 3:
      return fmt("volume %.4g m^3/s^3", m.polytope_volume_m3_s3());
    case 2:
      return fmt("area %.4g m^2/s^2 (flat)", m.polytope_area_m2_s2());
    default:
      return fmt("dimension %u: no motion across it", static_cast<unsigned>(m.polytope_dim()));
  }
}

// A joint position for people: deg for angular joints, m for prismatic ones.
std::string joint_value(const msg::JointState& m, const std::vector<double>& values,
                        std::size_t i) {
  if (i >= values.size()) return "-";
  return is_prismatic(m, i) ? fmt("%10.3f m  ", shown(values[i], 3))
                            : fmt("%10.1f deg", shown(values[i] * 180.0 / kPi, 1));
}

std::vector<std::string> render(const Snapshot& s, const DashboardOptions& o, std::int64_t now_ns,
                                bool live) {
  std::vector<std::string> lines;
  const bool st = s.has(Topic::kStatus), jo = s.has(Topic::kJoints), hy = s.has(Topic::kHydraulics),
             cp = s.has(Topic::kCommandPath);

  // Title, and the cycle and machine time of the sample that arrived last (by arrival, not by
  // cycle: a restarted craneassist counts from 0 again).
  std::string title = fmt("craneassist dashboard   domain %d", o.domain_id);
  if (st) {
    title += "   " + or_dash(s.status.crane()) + "   backend " + or_dash(s.status.backend());
  }
  lines.push_back(title);
  const msg::Header* newest = nullptr;
  std::int64_t newest_ns = 0;
  const msg::Header* headers[kTelemetryTopics] = {&s.status.header(), &s.joints.header(),
                                                  &s.hydraulics.header(), &s.command_path.header()};
  for (int i = 0; i < kTelemetryTopics; ++i) {
    if (s.received_ns[i] != 0 && s.received_ns[i] >= newest_ns) {
      newest = headers[i];
      newest_ns = s.received_ns[i];
    }
  }
  lines.push_back(newest != nullptr
                      ? fmt("cycle %llu   t %.2f s",
                            static_cast<unsigned long long>(newest->cycle()), newest->t_s())
                      : std::string("cycle -   t -"));
  lines.push_back("");

  // The loop's state (status topic).
  auto pair = [](const char* k1, const std::string& v1, const char* k2, const std::string& v2) {
    return fmt("%-10s%-24s%-14s%s", k1, v1.c_str(), k2, v2.c_str());
  };
  lines.push_back(pair("status", st ? or_dash(s.status.state()) : "-", "stop reason",
                       st ? or_dash(s.status.stop_reason()) : "-"));
  lines.push_back(pair("input", st ? or_dash(s.status.input_source()) : "-", "deadman",
                       st ? (s.status.deadman() ? "ON" : "off") : "-"));
  lines.push_back(pair("limit", st ? or_dash(s.status.active_limit()) : "-", "pump limiter",
                       st ? or_dash(s.status.pump_limit()) : "-"));
  lines.push_back(pair("scale",
                       cp   ? fmt("%.2f", s.command_path.scale())
                       : st ? fmt("%.2f", s.status.scale())
                            : "-",
                       "path speed", cp ? fmt("%.3f 1/s", s.command_path.sdot()) : "-"));
  lines.push_back(
      pair("loop", st ? fmt("worst start %.0f us", s.status.loop_latency_max_s() * 1e6) : "-",
           "overruns",
           st ? fmt("%llu", static_cast<unsigned long long>(s.status.loop_overruns())) : "-"));
  lines.push_back("");

  // The pump against its limits (hydraulics topic).
  constexpr int kBar = 30;
  if (hy) {
    const auto& h = s.hydraulics;
    lines.push_back(fmt("%-10s%s %6.1f / %6.1f kW     %s", "power",
                        bar(h.power_w(), h.power_limit_w(), kBar).c_str(), h.power_w() * 1e-3,
                        h.power_limit_w() * 1e-3, percent(h.power_w(), h.power_limit_w()).c_str()));
    lines.push_back(fmt("%-10s%s %6.1f / %6.1f L/min  %s", "flow",
                        bar(h.flow_m3_s(), h.flow_limit_m3_s(), kBar).c_str(), h.flow_m3_s() * 60e3,
                        h.flow_limit_m3_s() * 60e3,
                        percent(h.flow_m3_s(), h.flow_limit_m3_s()).c_str()));
    lines.push_back(fmt("%-10s%-16s pressure %.1f MPa   energy %.1f kJ", "pump",
                        or_dash(h.pump_mode()).c_str(), h.pressure_pa() * 1e-6,
                        h.energy_j() * 1e-3));
  } else {
    lines.push_back(fmt("%-10s-", "power"));
    lines.push_back(fmt("%-10s-", "flow"));
    lines.push_back(fmt("%-10s-", "pump"));
  }

  // The stick's speed against what the cylinders and the pump allow along its direction, and
  // the flow manipulability polytope (status; the stick's speed from command_path).
  if (st) {
    const double avail = s.status.avail_speed_m_s();
    const double stick = cp ? norm(s.command_path.command_m_s()) : NAN;  // NaN: no valid input
    const bool known = std::isfinite(stick);
    lines.push_back(fmt("%-10s%s %5s / %5.2f m/s available  %s", "stick",
                        bar(known ? stick : 0.0, avail, kBar).c_str(),
                        known ? fmt("%.2f", stick).c_str() : "-", avail,
                        known ? percent(stick, avail).c_str() : ""));
    lines.push_back(fmt("%-10s%-27s along the chosen joint motion %.2f m/s", "polytope",
                        polytope_measure(s.status).c_str(), s.status.avail_speed_resolved_m_s()));
  } else {
    lines.push_back(fmt("%-10s-", "stick"));
    lines.push_back(fmt("%-10s-", "polytope"));
  }

  // The load in the grapple (status): the crane scale and the load moment against the chart.
  if (st) {
    const auto& m = s.status;
    const bool chart = m.rated_load_kg() > 0.0;
    std::string truth;
    if (std::isfinite(m.load_truth_kg())) truth = fmt("  (simulated %.0f kg)", m.load_truth_kg());
    lines.push_back(fmt("%-10s%7.1f kg %-24s at %.2f m reach%s", "scale", m.payload_estimate_kg(),
                        m.payload_converged() ? "weighed" : "weighing (rated assumed)",
                        m.load_reach_m(), truth.c_str()));
    if (chart) {
      lines.push_back(fmt("%-10s%s %4.0f %% of %.0f kg rated  %s", "moment",
                          bar(m.load_moment_ratio(), 1.0, kBar).c_str(),
                          m.load_moment_ratio() * 100.0, m.rated_load_kg(),
                          m.overload()       ? "OVERLOAD: motions raising it stop"
                          : m.load_warning() ? "WARNING: 90 % of the chart"
                                             : ""));
    } else {
      lines.push_back(fmt("%-10sno load chart", "moment"));
    }
  } else {
    lines.push_back(fmt("%-10s-", "scale"));
    lines.push_back(fmt("%-10s-", "moment"));
  }

  // Operator command and scaled reference (command_path topic).
  lines.push_back(fmt("%-10s%s", "command",
                      cp ? xyz(s.command_path.command_m_s(), "%+7.3f", "m/s").c_str() : "-"));
  lines.push_back(fmt("%-10s%s", "reference",
                      cp ? xyz(s.command_path.reference_m_s(), "%+7.3f", "m/s").c_str() : "-"));
  lines.push_back("");

  // Joints, cylinders and the tip (joints topic).
  lines.push_back(fmt("%-10s%10s    %10s    %10s", "joint", "position", "reference", "cylinder"));
  if (jo) {
    const auto& j = s.joints;
    for (std::size_t i = 0; i < j.q().size(); ++i) {
      const std::string name = i < j.names().size() ? j.names()[i] : fmt("joint %zu", i);
      const std::string cyl =
          i < j.cylinder_pos_m().size() ? fmt("%10.3f m", j.cylinder_pos_m()[i]) : "-";
      lines.push_back(fmt("%-10s%s%s%s", name.c_str(), joint_value(j, j.q(), i).c_str(),
                          joint_value(j, j.q_ref(), i).c_str(), cyl.c_str()));
    }
    std::string tip = fmt("%-10s%s   speed %.2f m/s", "tip", xyz(j.tip_m(), "%+7.3f", "m").c_str(),
                          norm(j.tip_v_m_s()));
    if (st) tip += fmt("   error %.1f mm", s.status.tip_error_m() * 1e3);
    lines.push_back(tip);
  } else {
    lines.push_back("-");
    lines.push_back(fmt("%-10s-", "tip"));
  }
  // The wheeled base, when the crane stands on one (sim --drive): where it is, how fast it
  // goes, and the hub motors' flow against the drive pump.
  if (s.base_received_ns != 0) {
    const auto& b = s.base;
    const bool stale = static_cast<double>(now_ns - s.base_received_ns) * 1e-9 > kStaleS;
    lines.push_back(fmt("%-10sx %+8.3f  y %+8.3f m  heading %6.1f deg   %+.2f m/s  %+.1f deg/s%s",
                        "base", shown(b.pose()[0], 3), shown(b.pose()[1], 3),
                        shown(b.pose()[2] * 180.0 / kPi, 1), shown(b.velocity()[0], 2),
                        shown(b.velocity()[1] * 180.0 / kPi, 1), stale ? "   STALE" : ""));
    lines.push_back(fmt("%-10s%s %6.1f / %6.1f L/min  %s  %s", "drive",
                        bar(b.motor_flow_sum_m3_s(), b.drive_max_flow_m3_s(), kBar).c_str(),
                        b.motor_flow_sum_m3_s() * 60e3, b.drive_max_flow_m3_s() * 60e3,
                        percent(b.motor_flow_sum_m3_s(), b.drive_max_flow_m3_s()).c_str(),
                        b.shared_pump() ? "hub motors (the crane shares the pump)" : "hub motors"));
  }

  // How old each topic's latest sample is (by the clock of this host, at arrival), two topics
  // a line so that STALE fits in 80 columns.
  std::string ages;
  for (int i = 0; i < kTelemetryTopics; ++i) {
    std::string age_text = "-";
    if (s.received_ns[i] != 0) {
      const double age = static_cast<double>(now_ns - s.received_ns[i]) * 1e-9;
      age_text = fmt("%.2f s", age) + (age > kStaleS ? " STALE" : "");
    }
    ages += fmt("%-15s%-17s", std::string(topic_info(kTelemetry[i]).short_name).c_str(),
                age_text.c_str());
    if (i % 2 == 1) {
      lines.push_back(fmt("%-10s", i == 1 ? "age" : "") + ages);
      ages.clear();
    }
  }
  // Samples dropped because they could not be deserialized (only when there were any).
  std::uint64_t malformed = 0;
  std::string per_topic;
  for (int i = 0; i < kTelemetryTopics; ++i) {
    malformed += s.malformed[i];
    per_topic += fmt("%s%s %llu", i > 0 ? ", " : "",
                     std::string(topic_info(kTelemetry[i]).short_name).c_str(),
                     static_cast<unsigned long long>(s.malformed[i]));
  }
  if (malformed > 0) {
    lines.push_back(fmt("%-10s%llu malformed samples dropped (%s)", "dropped",
                        static_cast<unsigned long long>(malformed), per_topic.c_str()));
  }
  if (o.fields) {
    // Every value of the field table as craneassist/fields carries it, three to a line.
    lines.emplace_back();
    const auto& f = s.fields;
    if (s.fields_received_ns == 0) {
      lines.push_back(fmt("%-10swaiting for craneassist/fields", "fields"));
    } else {
      const std::size_t n = std::min(f.names().size(), f.values().size());
      std::string line;
      for (std::size_t i = 0; i < n; ++i) {
        const std::string unit = i < f.units().size() ? f.units()[i] : "";
        line += fmt("%-26.26s%11.4g %-9.9s", f.names()[i].c_str(), f.values()[i],
                    unit == "1" ? "" : unit.c_str());
        if (i % 3 == 2 || i + 1 == n) {
          lines.push_back(line);
          line.clear();
        }
      }
    }
  }
  if (live) lines.push_back("q or Ctrl-C quits");
  for (auto& line : lines) line.erase(line.find_last_not_of(' ') + 1);
  return lines;
}

std::vector<std::string> waiting_screen(const Snapshot& s, const DashboardOptions& o,
                                        double elapsed_s) {
  std::string matched;
  for (int i = 0; i < kTelemetryTopics; ++i) {
    matched += fmt("%s%s %d", i > 0 ? ", " : "",
                   std::string(topic_info(kTelemetry[i]).short_name).c_str(), s.matched[i]);
  }
  return {fmt("craneassist dashboard: waiting for craneassist on domain %d ...", o.domain_id),
          "",
          fmt("  %.0f s; writers discovered: %s", elapsed_s, matched.c_str()),
          "  (craneassist publishes telemetry while it runs: sim, replay)",
          "",
          "q or Ctrl-C quits"};
}

// The live view's terminal: cursor hidden, keys read without echo (Ctrl-C still signals);
// restored by the destructor.
class LiveTerminal {
 public:
  explicit LiveTerminal(std::FILE* out) : out_(out) {
    if (isatty(STDIN_FILENO) != 0 && tcgetattr(STDIN_FILENO, &saved_) == 0) {
      termios raw = saved_;
      raw.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO);
      raw.c_cc[VMIN] = 0;
      raw.c_cc[VTIME] = 0;
      keys_ = tcsetattr(STDIN_FILENO, TCSANOW, &raw) == 0;
    }
    std::fputs("\033[?25l\033[H\033[2J", out_);
    std::fflush(out_);
  }
  ~LiveTerminal() {
    std::fputs("\033[?25h\n", out_);  // the cursor back, below the last view
    std::fflush(out_);
    if (keys_) tcsetattr(STDIN_FILENO, TCSANOW, &saved_);
  }
  LiveTerminal(const LiveTerminal&) = delete;
  LiveTerminal& operator=(const LiveTerminal&) = delete;

  // Full redraw from the top left; lines cut to the terminal (one column spare, so no line
  // wraps), every line and the rest of the screen erased.
  void draw(const std::vector<std::string>& lines) {
    int columns = 80, rows = 24;
    winsize ws{};
    if (ioctl(fileno(out_), TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 && ws.ws_row > 0) {
      columns = ws.ws_col;
      rows = ws.ws_row;
    }
    std::string frame = "\033[H";
    const std::size_t n = std::min(lines.size(), static_cast<std::size_t>(rows));
    for (std::size_t i = 0; i < n; ++i) {
      frame += lines[i].substr(0, static_cast<std::size_t>(std::max(columns - 1, 1)));
      frame += "\033[K";
      if (i + 1 < n) frame += "\n";
    }
    frame += "\033[J";
    std::fputs(frame.c_str(), out_);
    std::fflush(out_);
  }

  // Waits up to max_s for a key; true when it is q (quit), or when the terminal is gone. A
  // signal ends the wait early.
  bool wait_for_quit(double max_s) {
    const int ms = static_cast<int>(std::lround(max_s * 1e3));
    if (!keys_) {
      poll(nullptr, 0, ms);
      return false;
    }
    pollfd fd{STDIN_FILENO, POLLIN, 0};
    if (poll(&fd, 1, ms) <= 0) return false;
    char buf[64];
    const ssize_t n = read(STDIN_FILENO, buf, sizeof buf);
    if (n == 0) return true;  // readable but nothing to read: hung up
    if (n < 0) return errno != EINTR && errno != EAGAIN;
    for (ssize_t i = 0; i < n; ++i) {
      if (buf[i] == 'q' || buf[i] == 'Q') return true;
    }
    return false;
  }

 private:
  std::FILE* out_;
  termios saved_{};
  bool keys_ = false;
};

int report_timeout(const Snapshot& s, const DashboardOptions& o) {
  std::string missing;
  for (int i = 0; i < kTelemetryTopics; ++i) {
    if (s.received_ns[i] != 0) continue;
    if (!missing.empty()) missing += ", ";
    missing += std::string(topic_info(kTelemetry[i]).dds_name);
  }
  std::fprintf(o.err,
               "craneassist: error: no sample on %s within %g s on domain %d; is craneassist sim "
               "running with telemetry on?\n",
               missing.c_str(), o.timeout_s, o.domain_id);
  return kToolRuntime;
}

}  // namespace

std::vector<std::string> dashboard_view(const msg::Status* status, const msg::JointState* joints,
                                        const msg::Hydraulics* hydraulics,
                                        const msg::CommandPath* command_path,
                                        const msg::BaseState* base) {
  Snapshot s;
  const std::int64_t now_ns = monotonic_ns();
  if (base != nullptr) {
    s.base = *base;
    s.base_received_ns = now_ns;
  }
  if (status != nullptr) {
    s.status = *status;
    s.received_ns[index_of(Topic::kStatus)] = now_ns;
  }
  if (joints != nullptr) {
    s.joints = *joints;
    s.received_ns[index_of(Topic::kJoints)] = now_ns;
  }
  if (hydraulics != nullptr) {
    s.hydraulics = *hydraulics;
    s.received_ns[index_of(Topic::kHydraulics)] = now_ns;
  }
  if (command_path != nullptr) {
    s.command_path = *command_path;
    s.received_ns[index_of(Topic::kCommandPath)] = now_ns;
  }
  return render(s, DashboardOptions{}, now_ns, false);
}

int run_dashboard(const DashboardOptions& o) {
  if (!(o.timeout_s >= 0.0) || !(o.refresh_s > 0.0)) {
    std::fprintf(o.err, "craneassist: error: --timeout must not be negative\n");
    return kToolUsage;
  }
  LatestSamples latest;
  const auto session = open_tool_session(
      "craneassist-dashboard", o.domain_id, o.transport, o.type_propagation,
      std::vector<Topic>{Topic::kStatus, Topic::kJoints, Topic::kHydraulics, Topic::kCommandPath,
                         Topic::kBase, Topic::kFields},
      o.err, [&latest](Topic topic, fdds::DataReader& reader) { latest.take(topic, reader); });
  if (!session) return kToolRuntime;
  auto snapshot = [&] {
    Snapshot s = latest.copy();
    for (int i = 0; i < kTelemetryTopics; ++i) {
      s.matched[i] = session->reader(kTelemetry[i]).matched_writers();
    }
    return s;
  };
  auto timed_out = [&] { return o.timeout_s > 0.0 && session->elapsed_s() >= o.timeout_s; };

  const bool live = !o.once && isatty(fileno(o.out)) != 0;
  if (!live) {
    while (!stop_requested()) {
      const Snapshot s = snapshot();
      if (s.all() && (!o.fields || s.fields_received_ns != 0)) {
        for (const auto& line : render(s, o, monotonic_ns(), false)) {
          std::fprintf(o.out, "%s\n", line.c_str());
        }
        std::fflush(o.out);
        return kToolOk;
      }
      if (timed_out()) return report_timeout(s, o);
      session->wakeup().wait(0.05);
    }
    return kToolOk;
  }

  int rc = kToolOk;
  Snapshot s;
  {
    LiveTerminal terminal(o.out);
    while (!stop_requested()) {
      s = snapshot();
      if (!s.all() && timed_out()) {
        rc = kToolRuntime;
        break;
      }
      terminal.draw(s.any() ? render(s, o, monotonic_ns(), true)
                            : waiting_screen(s, o, session->elapsed_s()));
      if (terminal.wait_for_quit(o.refresh_s)) break;
    }
  }  // the terminal restored before any message
  if (rc == kToolRuntime) report_timeout(s, o);
  return rc;
}

}  // namespace craneassist::dds
