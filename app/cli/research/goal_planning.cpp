#include "research/goal_planning.hpp"

#include <poll.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace craneassist::cli {
namespace {

// "X,Z" as two finite numbers; nullopt otherwise.
std::optional<Eigen::Vector2d> parse_xz(const std::string& text) {
  const auto comma = text.find(',');
  if (comma == std::string::npos) return std::nullopt;
  const std::string a = text.substr(0, comma), b = text.substr(comma + 1);
  char* end = nullptr;
  const double x = std::strtod(a.c_str(), &end);
  if (a.empty() || *end != '\0' || !std::isfinite(x)) return std::nullopt;
  const double z = std::strtod(b.c_str(), &end);
  if (b.empty() || *end != '\0' || !std::isfinite(z)) return std::nullopt;
  return Eigen::Vector2d(x, z);
}

// A typed line as it may be shown: at most 40 characters, other than printable ASCII as '?'.
std::string printable(const std::string& text) {
  std::string out = text.substr(0, 40);
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  }
  return text.size() > 40 ? out + "..." : out;
}

// The longest goal line taken; more without an end of line is dropped.
constexpr std::size_t kMaxGoalLine = 256;

double smoothstep(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * (3.0 - 2.0 * u);
}

double smoothstep_rate(double u) {
  return u <= 0.0 || u >= 1.0 ? 0.0 : 6.0 * u * (1.0 - u);
}

}  // namespace

std::vector<GoalAt> parse_goals(const std::string& goal, const std::vector<std::string>& goal_at) {
  std::vector<GoalAt> goals;
  if (!goal.empty()) {
    const auto xz = parse_xz(goal);
    if (!xz) throw CLI::ValidationError("--goal", "'" + goal + "': expected X,Z in m, e.g. 6,2");
    goals.push_back({0.0, *xz});
  }
  for (const std::string& entry : goal_at) {
    const auto colon = entry.find(':');
    const std::string when = colon == std::string::npos ? "" : entry.substr(0, colon);
    char* end = nullptr;
    const double t = std::strtod(when.c_str(), &end);
    const auto xz = colon == std::string::npos ? std::nullopt : parse_xz(entry.substr(colon + 1));
    if (when.empty() || *end != '\0' || !std::isfinite(t) || t < 0.0 || !xz) {
      throw CLI::ValidationError(
          "--goal-at",
          "'" + entry + "': expected T:X,Z (seconds from the start, then m), e.g. 5:7,1");
    }
    goals.push_back({t, *xz});
  }
  std::stable_sort(goals.begin(), goals.end(),
                   [](const GoalAt& a, const GoalAt& b) { return a.t_s < b.t_s; });
  for (std::size_t k = 1; k < goals.size(); ++k) {
    if (goals[k].t_s == goals[k - 1].t_s) {
      throw CLI::ValidationError("--goal-at",
                                 "two goals at " + std::to_string(goals[k].t_s) + " s");
    }
  }
  return goals;
}

std::vector<input::TipSample> tip_trajectory(const planner::PlanarArm& arm,
                                             const planner::PtpPlan& plan,
                                             const Eigen::Vector3d& tip_now_m,
                                             const Eigen::Vector2d& goal_xz,
                                             const TipLimits& limits) {
  std::vector<input::TipSample> out;
  if (plan.samples.empty()) return out;
  dynamics::KinematicsData data;
  planner::ArmJacobian jacobian;
  const Eigen::Matrix<double, 3, 2> to_crane = arm.plane().transpose();
  out.reserve(plan.samples.size());
  for (const auto& s : plan.samples) {
    const Eigen::Vector2d xz = arm.tip(s.q, data);
    arm.jacobian(s.q, data, jacobian);
    out.push_back({s.t_s, arm.from_plane(xz), to_crane * (jacobian * s.qdot)});
  }
  const double t0 = out.front().t_s, duration = out.back().t_s - t0;
  const Eigen::Vector3d start_offset = tip_now_m - out.front().p_m;
  const Eigen::Vector3d end_offset = arm.from_plane(goal_xz) - out.back().p_m;
  for (auto& s : out) {
    const double u = duration > 0.0 ? (s.t_s - t0) / duration : 1.0;
    const double w = smoothstep(u);
    s.p_m += (1.0 - w) * start_offset + w * end_offset;
    if (duration > 0.0) s.v_m_s += (end_offset - start_offset) * smoothstep_rate(u) / duration;
    s.t_s -= t0;
  }
  double peak = 0.0, peak_acceleration = 0.0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    peak = std::max(peak, out[k].v_m_s.norm());
    if (k > 0 && out[k].t_s > out[k - 1].t_s) {
      peak_acceleration = std::max(peak_acceleration, (out[k].v_m_s - out[k - 1].v_m_s).norm() /
                                                          (out[k].t_s - out[k - 1].t_s));
    }
  }
  double stretch = 1.0;
  if (limits.speed_m_s > 0.0) stretch = std::max(stretch, peak / limits.speed_m_s);
  if (limits.acceleration_m_s2 > 0.0) {
    stretch = std::max(stretch, std::sqrt(peak_acceleration / (0.5 * limits.acceleration_m_s2)));
  }
  if (stretch > 1.0) {
    for (auto& s : out) {
      s.t_s *= stretch;
      s.v_m_s /= stretch;
    }
  }
  return out;
}

GoalPlanner::GoalPlanner(planner::PtpPlanner& planner, input::GoalSource& source,
                         std::vector<GoalAt> goals, const planner::PtpWeights& weights,
                         const TipLimits& limits, bool read_stdin)
    : planner_(planner),
      source_(source),
      goals_(std::move(goals)),
      weights_(weights),
      limits_(limits),
      read_stdin_(read_stdin) {}

GoalPlanner::~GoalPlanner() {
  stop();
}

void GoalPlanner::start() {
  stop_ = false;
  thread_ = std::thread([this] { run(); });
}

void GoalPlanner::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

std::vector<std::string> GoalPlanner::report() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> lines = report_;
  if (unlisted_ > 0) {
    lines.push_back("(" + std::to_string(unlisted_) + " more goals, not listed)");
  }
  return lines;
}

void GoalPlanner::plan_to(const Eigen::Vector2d& goal, const Eigen::Vector3d& tip, double now_s,
                          const char* origin) {
  const planner::PlanarArm& arm = planner_.arm();
  const Eigen::Vector2d from = arm.to_plane(tip);
  char head[160];
  // A goal far outside any workspace in %g, not in hundreds of digits.
  const char* format = goal.cwiseAbs().maxCoeff() < 1e6 ? "goal (%.2f, %.2f) m %s at %.2f s"
                                                        : "goal (%.3g, %.3g) m %s at %.2f s";
  std::snprintf(head, sizeof head, format, goal.x(), goal.y(), origin,
                now_s - start_s_.value_or(now_s));
  std::string line = head;
  bool refused = false;
  try {
    const planner::PtpPlan plan = planner_.plan(from, goal, weights_);
    if (!plan.path.found || plan.samples.empty()) {
      line += ": no path (the arm cannot get there from here)";
      refused = true;
    } else {
      const auto samples = tip_trajectory(arm, plan, tip, goal, limits_);
      if (!source_.publish(samples, now_s)) {
        line += ": the plan is too long for the goal input (" + std::to_string(samples.size()) +
                " samples)";
      } else {
        char text[200];
        std::snprintf(text, sizeof text,
                      ": planned in %.2f ms: %.2f m, %.1f kJ at the planner's speeds (%.1f s), "
                      "followed in %.1f s",
                      plan.planning_time_s * 1e3, plan.length_m, plan.energy_j * 1e-3, plan.time_s,
                      samples.back().t_s);
        line += text;
      }
    }
  } catch (const std::exception& e) {
    line += std::string(": refused: ") + e.what();
    refused = true;
  }
  if (refused) {
    spdlog::warn("{}", line);
  } else {
    spdlog::info("{}", line);
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (report_.size() < kMaxReportedGoals) {
    report_.push_back(line);
  } else {
    ++unlisted_;  // a script typing goals without end: the summary stays short
  }
}

void GoalPlanner::run() {
  std::size_t next = 0;
  while (!stop_) {
    Eigen::Vector3d tip;
    double now = 0.0;
    if (source_.last_tip(tip, now)) {
      if (!start_s_) start_s_ = now;
      while (next < goals_.size() && now - *start_s_ >= goals_[next].t_s) {
        plan_to(goals_[next].xz, tip, now,
                next == 0 && goals_[next].t_s == 0.0 ? "from the start" : "on schedule");
        ++next;
      }
    }
    if (read_stdin_) {
      pollfd fd{0, POLLIN, 0};
      if (::poll(&fd, 1, 10) > 0 && (fd.revents & (POLLIN | POLLHUP))) {
        char buffer[256];
        const ssize_t n = ::read(0, buffer, sizeof buffer);
        if (n <= 0) {
          read_stdin_ = false;  // end of input: the scheduled goals go on
        } else {
          stdin_buffer_.append(buffer, static_cast<std::size_t>(n));
          if (stdin_buffer_.size() > kMaxGoalLine &&
              stdin_buffer_.find('\n') == std::string::npos) {
            // Not a goal: bytes without an end of line. Drop them rather than grow without end.
            spdlog::warn(
                "goal input: {} bytes without an end of line, dropped (expected X,Z lines)",
                stdin_buffer_.size());
            stdin_buffer_.clear();
          }
          std::size_t eol;
          while ((eol = stdin_buffer_.find('\n')) != std::string::npos) {
            std::string text = stdin_buffer_.substr(0, eol);
            stdin_buffer_.erase(0, eol + 1);
            text.erase(std::remove_if(text.begin(), text.end(),
                                      [](unsigned char c) { return std::isspace(c) != 0; }),
                       text.end());
            if (text.empty()) continue;
            const auto xz = parse_xz(text);
            if (!xz) {
              spdlog::warn("goal '{}': expected X,Z in m, e.g. 6,2", printable(text));
            } else if (source_.last_tip(tip, now)) {
              plan_to(*xz, tip, now, "typed");
            } else {
              spdlog::warn("goal '{}': no tip measurement yet", printable(text));
            }
          }
        }
      }
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
}

}  // namespace craneassist::cli
