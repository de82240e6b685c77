#include "craneassist/offline/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>
#include <stdexcept>
#include <utility>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/valve_table.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"
#include "craneassist/valves/proportional_valves.hpp"

namespace craneassist::offline {
namespace {

// The velocity, as a share of the section's top speed, at which a level counts as moving
// (identify_valve_dynamics); a misfit of the onsets up to this is never refused.
constexpr double kOnsetShare = 0.003;
constexpr double kMinOnsetResidualS = 0.005;

// The joint position of section i at the middle of its cylinder stroke (c(q) is monotone over the
// joint range, config checks that).
double mid_stroke_q(const dynamics::CraneModel& model, int i) {
  const auto& joint = model.joints[static_cast<std::size_t>(i)];
  const auto& cyl = model.cylinders[static_cast<std::size_t>(i)];
  const double c_lo = dynamics::cylinder_length(cyl, joint.q_min);
  const double c_hi = dynamics::cylinder_length(cyl, joint.q_max);
  const double target = 0.5 * (c_lo + c_hi);
  double a = joint.q_min, b = joint.q_max;
  for (int k = 0; k < 100; ++k) {
    const double m = 0.5 * (a + b);
    const bool below = (dynamics::cylinder_length(cyl, m) < target) == (c_lo < c_hi);
    (below ? a : b) = m;
  }
  return 0.5 * (a + b);
}

// The sweep of one section as a cycle task, on the simulator and on a machine alike. For every
// signed command in turn: (on a machine) move the section to mid-stroke and wait for rest, then
// hold the command for settle + measure cycles with every other valve neutral and measure the
// steady cylinder velocity: the mean over the window after the settle time, invalid when the two
// halves of the window differ or the cylinder comes near an end stop. The velocity comes from
// the joint feedback (positions on the simulator, rates on a machine: level_step) through the
// model's joint-to-cylinder kinematics, the same on both, so a machine's table and the
// simulator's compare.
//
// Placed (the simulator): the machine starts each level at mid-stroke and at rest, so the task
// holds its one level from the first cycle and finishes after the window; the spool steps.
// On a machine: the moves, spools closed at a limited rate, a level cut short before the
// cylinder can reach the end margin, a level that did not settle measured again, and neutral
// spools at the end or on a stop request.
class SweepTask final : public control::CycleTask {
 public:
  enum class Mode { kPlaced, kMachine };

  SweepTask(const config::CraneConfig& config, int section, std::vector<double> commands,
            const CalibrationOptions& options, Mode mode, std::vector<SweepLogRow>* log)
      : cyl_(config.model.cylinders[static_cast<std::size_t>(section)]),
        valves_(config.model, 0.0),
        section_(section),
        mode_(mode),
        commands_(std::move(commands)),
        period_s_(1.0 / config.control.rate_hz),
        settle_(static_cast<int>(std::lround(options.settle_s / period_s_))),
        measure_(std::max(1, static_cast<int>(std::lround(options.measure_s / period_s_)))),
        half_(settle_ + measure_ / 2),
        tolerance_(mode == Mode::kMachine ? options.machine_settled_tolerance
                                          : options.settled_tolerance),
        retries_(mode == Mode::kMachine ? std::max(0, options.machine_retries) : 0),
        log_(log) {
    const auto& joint = config.model.joints[static_cast<std::size_t>(section)];
    const double c_a = dynamics::cylinder_length(cyl_, joint.q_min);
    const double c_b = dynamics::cylinder_length(cyl_, joint.q_max);
    const double stroke = std::abs(c_b - c_a);
    const double margin = options.end_margin * stroke;
    c_lo_ = std::min(c_a, c_b) + margin;
    c_hi_ = std::max(c_a, c_b) - margin;
    c_mid_ = 0.5 * (c_a + c_b);
    const auto& move = options.move;
    gain_1_s_ = move.gain_1_s;
    speed_cap_m_s_ = move.speed_fraction * cyl_.v_max_m_s;
    spool_max_ = move.spool_max;
    position_tolerance_m_ = move.tolerance * stroke;
    rest_speed_m_s_ = move.rest_speed_fraction * cyl_.v_max_m_s;
    rest_cycles_ = std::max(1, static_cast<int>(std::lround(move.rest_s / period_s_)));
    move_timeout_cycles_ = static_cast<long>(std::ceil(move.timeout_s / period_s_));
    spool_step_ = move.spool_rate_1_s * period_s_;
    spool_rate_1_s_ = move.spool_rate_1_s;
    valve_lag_s_ = dynamics::section_delay_s(config.model, section) +
                   dynamics::section_time_constant_s(config.model, section);
    const int dof = config.model.dof();
    spool_.setZero(dof);
    target_.setZero(dof);
    points_.reserve(commands_.size());
    if (log_ != nullptr) {
      log_->reserve(log_->size() + commands_.size() * static_cast<std::size_t>(1 + retries_) *
                                       static_cast<std::size_t>(settle_ + measure_ + 1));
    }
    phase_ = mode_ == Mode::kMachine ? Phase::kMove : Phase::kLevel;
  }

  void start(const valves::MachineState&, double) override {}

  control::CycleStatus step(const control::CycleTime& time, const valves::MachineState& state,
                            const char* stop_cause, valves::ValveCommand& command,
                            control::LogRow& row) noexcept override {
    if (stop_cause != nullptr && phase_ != Phase::kEnd) phase_ = Phase::kEnd;  // level dropped
    target_.setZero();
    if (phase_ == Phase::kMove) move_step(state);
    if (phase_ == Phase::kLevel) level_step(state);
    if (mode_ == Mode::kMachine) {  // closing ramped, opening as commanded (MidStrokeMove)
      for (Eigen::Index j = 0; j < spool_.size(); ++j) {
        const double now = spool_[j], wanted = target_[j];
        const bool opens = now == 0.0 || (wanted * now > 0.0 && std::abs(wanted) >= std::abs(now));
        double next = opens ? wanted : now + std::clamp(wanted - now, -spool_step_, spool_step_);
        if (next * now < 0.0) next = 0.0;  // reversing: neutral first, the other side opens next
        spool_[j] = next;
      }
    } else {
      spool_ = target_;
    }
    command.spool = spool_;
    row.t = time.t_s;
    for (Eigen::Index j = 0; j < spool_.size() && j < state.q.size(); ++j) {
      row.q[static_cast<std::size_t>(j)] = state.q[j];
      row.spool[static_cast<std::size_t>(j)] = spool_[j];
    }
    row.set_pump(state.pump);
    if (phase_ == Phase::kEnd && all_neutral()) {
      finished_ = true;
      return control::CycleStatus::kStopped;
    }
    return stop_cause != nullptr ? control::CycleStatus::kStopping : control::CycleStatus::kRunning;
  }

  bool finished() const noexcept override { return finished_; }
  const std::vector<SweepPoint>& points() const { return points_; }
  // Cycles of one level held to its end: the settle time and the window.
  long level_cycles() const { return settle_ + measure_ + 1; }
  bool not_positioned() const { return not_positioned_; }

 private:
  enum class Phase { kMove, kLevel, kEnd };

  bool all_neutral() const noexcept {
    for (Eigen::Index j = 0; j < spool_.size(); ++j) {
      if (spool_[j] != 0.0) return false;
    }
    return true;
  }

  // Towards mid-stroke: P on the cylinder position, capped, through the valve model; within the
  // tolerance neutral, and the level starts (this same cycle) once the cylinder has been at rest
  // there for rest_cycles_ with the spool back at neutral.
  void move_step(const valves::MachineState& state) noexcept {
    if (++move_cycles_ > move_timeout_cycles_) {
      not_positioned_ = true;
      phase_ = Phase::kEnd;
      return;
    }
    if (!state.valid) {
      rest_count_ = 0;
      return;
    }
    const double q = state.q[section_];
    const double error_m = c_mid_ - dynamics::cylinder_length(cyl_, q);
    const double speed_m_s = dynamics::cylinder_arm(cyl_, q) * state.qdot[section_];
    if (std::abs(error_m) > position_tolerance_m_) {
      rest_count_ = 0;
      const double v_ref = std::clamp(gain_1_s_ * error_m, -speed_cap_m_s_, speed_cap_m_s_);
      target_[section_] = std::clamp(valves_.spool_for(section_, v_ref), -spool_max_, spool_max_);
      return;
    }
    const bool at_rest = std::abs(speed_m_s) < rest_speed_m_s_ && spool_[section_] == 0.0;
    rest_count_ = at_rest ? rest_count_ + 1 : 0;
    if (rest_count_ >= rest_cycles_) start_level();
  }

  // How far the cylinder still goes when its level ends now: the spool ramps from the level to
  // the dead-band edge (the flow falling about linearly to zero), then the valve's dead time and
  // lag pass.
  double stopping_distance_m(double velocity_m_s) const noexcept {
    const double spool = spool_[section_];
    const double open = std::abs(spool) - std::abs(valves_.dead_band_edge(section_, spool));
    const double ramp_s = std::max(open, 0.0) / spool_rate_1_s_;
    return velocity_m_s * (0.5 * ramp_s + valve_lag_s_);
  }

  void start_level() noexcept {
    phase_ = Phase::kLevel;
    level_k_ = 0;
    level_valid_ = true;
    v_sum_1_ = v_sum_2_ = 0.0;
  }

  // One cycle of the level in progress: the command held, the window's samples, the log row.
  void level_step(const valves::MachineState& state) noexcept {
    const double command = commands_[next_];
    if (!state.valid) {  // no measurement (a machine's lost feedback): neutral, level dropped
      end_level({command, 0.0, false});
      return;
    }
    const int k = level_k_;
    const double q = state.q[section_];
    const double length = dynamics::cylinder_length(cyl_, q);
    const double velocity = dynamics::cylinder_arm(cyl_, q) * state.qdot[section_];
    const bool measuring = k >= settle_;
    if (k == settle_) c_start_ = length;
    if (k == half_) c_half_ = length;
    if (k > settle_) (k <= half_ ? v_sum_1_ : v_sum_2_) += velocity;
    if (measuring && (length < c_lo_ || length > c_hi_)) level_valid_ = false;
    bool cut = false;
    if (mode_ == Mode::kMachine) {
      // Keep the stroke margins on a machine: end the level while the cylinder can still stop
      // short of them (running into an end stop at full command is what must not happen).
      const double ahead = length + stopping_distance_m(velocity);
      cut = ahead < c_lo_ || ahead > c_hi_;
    }
    target_[section_] = cut ? 0.0 : command;
    if (log_ != nullptr) {
      log_->push_back(
          {section_, command, static_cast<double>(k) * period_s_, length, velocity, measuring});
    }
    if (k == settle_ + measure_) {
      // The mean velocity over the window and over its two halves. On the simulator every read
      // is a fresh sample taken at the cycle's time, so the position differences are exact. On
      // a machine the positions arrive at the sensors' own cycle (10 ms over CAN) and a read
      // gets the latest one, up to a cycle old: over a 0.15 s half window that moves the
      // difference by several per cent. The machine's joint rate is differentiated between the
      // frames' own time stamps (can::CanBackend), so there the mean of the rates is used.
      const double t_1 = (half_ - settle_) * period_s_,
                   t_2 = (settle_ + measure_ - half_) * period_s_;
      SweepPoint point{command, 0.0, level_valid_};
      double v1 = 0.0, v2 = 0.0;
      if (mode_ == Mode::kMachine) {
        point.velocity_m_s = (v_sum_1_ + v_sum_2_) / measure_;
        v1 = v_sum_1_ / (half_ - settle_);
        v2 = v_sum_2_ / (settle_ + measure_ - half_);
      } else {
        point.velocity_m_s = (length - c_start_) / (measure_ * period_s_);
        v1 = (c_half_ - c_start_) / t_1;
        v2 = (length - c_half_) / t_2;
      }
      const double scale = std::max(std::abs(point.velocity_m_s), 1e-3 * cyl_.v_max_m_s);
      if (std::abs(v2 - v1) > tolerance_ * scale) {
        point.valid = false;
        // Not settled on a machine: a disturbance (a stalled sensor frame, a load swing) is
        // likelier than a level that never settles; measure it again while tries remain.
        if (level_valid_ && tries_ < retries_) {
          ++tries_;
          phase_ = Phase::kMove;
          move_cycles_ = 0;
          rest_count_ = 0;
          return;
        }
      }
      end_level(point);
    } else if (cut) {
      end_level({command, 0.0, false});
    } else {
      ++level_k_;
    }
  }

  // The level's point recorded; the next level from the next cycle (on a machine after a move),
  // or the end of the sweep.
  void end_level(const SweepPoint& point) noexcept {
    points_.push_back(point);  // reserved for every command
    ++next_;
    tries_ = 0;
    if (next_ < commands_.size()) {
      if (mode_ == Mode::kMachine) {
        phase_ = Phase::kMove;
        move_cycles_ = 0;
        rest_count_ = 0;
      } else {
        start_level();
      }
    } else if (mode_ == Mode::kMachine) {
      phase_ = Phase::kEnd;  // spools ramp to neutral, then the run ends
    } else {
      finished_ = true;  // the simulator is set aside as it is
    }
  }

  const dynamics::Cylinder& cyl_;
  valves::ProportionalValves valves_;
  int section_;
  Mode mode_;
  std::vector<double> commands_;
  double period_s_;
  int settle_, measure_, half_;
  double tolerance_;
  int retries_;
  std::vector<SweepLogRow>* log_;
  double c_lo_ = 0.0, c_hi_ = 0.0, c_mid_ = 0.0;
  double gain_1_s_ = 0.0, speed_cap_m_s_ = 0.0, spool_max_ = 0.0, position_tolerance_m_ = 0.0;
  double rest_speed_m_s_ = 0.0, spool_step_ = 0.0, spool_rate_1_s_ = 1.0, valve_lag_s_ = 0.0;
  int rest_cycles_ = 1;
  long move_timeout_cycles_ = 0;

  Phase phase_ = Phase::kLevel;
  std::size_t next_ = 0;  // index of the level in progress
  int level_k_ = 0;       // cycle within the level
  bool level_valid_ = true;
  double c_start_ = 0.0, c_half_ = 0.0;
  double v_sum_1_ = 0.0, v_sum_2_ = 0.0;  // cylinder velocity over the window's halves
  long move_cycles_ = 0;
  int rest_count_ = 0;
  int tries_ = 0;  // repeats of the level in progress
  bool not_positioned_ = false;
  bool finished_ = false;
  dynamics::JointVector spool_, target_;
  std::vector<SweepPoint> points_;
};

// Every level in both directions, in the order swept: -l, +l for each level l.
std::vector<double> signed_commands(const std::vector<double>& levels) {
  std::vector<double> out;
  for (double level : levels) {
    for (double sign : {-1.0, 1.0}) out.push_back(sign * level);
  }
  return out;
}

// The fitted table of a section's sweep points (the (0, 0) point added).
SectionCalibration fit_section(int section, std::vector<SweepPoint> points,
                               const CalibrationOptions& options) {
  SectionCalibration result;
  result.section = section;
  result.points.push_back({0.0, 0.0, true});
  result.points.insert(result.points.end(), points.begin(), points.end());
  std::sort(result.points.begin(), result.points.end(),
            [](const SweepPoint& a, const SweepPoint& b) { return a.command < b.command; });
  double top = 0.0;
  for (const auto& p : result.points) top = std::max(top, std::abs(p.velocity_m_s));
  result.table = fit_valve_table(result.points, options.zero_fraction * top);
  if (dynamics::check_valve_table(result.table).empty()) {
    result.dead_band_retract = dynamics::valve_table_dead_band_edge(result.table, -1.0);
    result.dead_band_extend = dynamics::valve_table_dead_band_edge(result.table, 1.0);
    result.max_retract_m_s = -result.table.velocity_m_s.front();
    result.max_extend_m_s = result.table.velocity_m_s.back();
  }
  return result;
}

// When a level's cylinder starts to move: the first time its velocity passes threshold_m_s the
// level's way, interpolated between the cycles (NaN: never, or already at the level's start).
double onset_time(const std::vector<const SweepLogRow*>& level, double threshold_m_s) {
  const double side = level.front()->command > 0.0 ? 1.0 : -1.0;
  for (std::size_t k = 1; k < level.size(); ++k) {
    const double v0 = side * level[k - 1]->cylinder_velocity_m_s;
    const double v1 = side * level[k]->cylinder_velocity_m_s;
    if (v0 < threshold_m_s && v1 >= threshold_m_s) {
      const double w = (threshold_m_s - v0) / (v1 - v0);
      return level[k - 1]->t_s + w * (level[k]->t_s - level[k - 1]->t_s);
    }
    if (v0 >= threshold_m_s) break;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

void check_section(const dynamics::CraneModel& model, int section) {
  if (section < 0 || section >= model.dof()) throw std::invalid_argument("no such section");
}

std::string format_list(const std::vector<double>& values) {
  std::string out;
  char buf[32];
  for (double v : values) {
    std::snprintf(buf, sizeof buf, "%.6g", std::abs(v) < 1e-12 ? 0.0 : v);
    if (!out.empty()) out += ' ';
    out += buf;
  }
  return out;
}

}  // namespace

ValveDynamics identify_valve_dynamics(const dynamics::ValveTable& table,
                                      std::span<const SweepLogRow> rows, int section,
                                      double max_residual) {
  ValveDynamics out;
  if (const std::string why = dynamics::check_valve_table(table); !why.empty()) {
    out.why_not = "no usable table (" + why + ")";
    return out;
  }
  const double top = std::max(-table.velocity_m_s.front(), table.velocity_m_s.back());
  const double threshold = kOnsetShare * top;
  // Each level's onset against ln(c / (c - x_on)), x_on the command at which the table passes
  // the threshold: t_on = delay + time_constant * ln(c / (c - x_on)) for a spool that follows a
  // step to c after the delay with a first-order lag.
  std::vector<double> xs, ts;
  std::vector<const SweepLogRow*> level;
  auto close_level = [&] {
    if (level.size() < 2) {
      level.clear();
      return;
    }
    const double c = level.front()->command;
    const double side = c > 0.0 ? 1.0 : -1.0;
    const double x_on = std::abs(dynamics::valve_table_command(table, side * threshold));
    // Levels that move clearly (10 % of the top speed), with room between onset and level.
    if (side * dynamics::valve_table_velocity(table, c) >= 0.1 * top && std::abs(c) > x_on) {
      const double t_on = onset_time(level, threshold);
      if (std::isfinite(t_on)) {
        xs.push_back(std::log(std::abs(c) / (std::abs(c) - x_on)));
        ts.push_back(t_on);
      }
    }
    level.clear();
  };
  for (const auto& row : rows) {
    if (row.section != section) continue;
    if (row.t_s == 0.0) close_level();  // a level (or a level measured again) starts
    level.push_back(&row);
  }
  close_level();
  out.levels = static_cast<int>(xs.size());
  if (xs.size() < 3) {
    out.why_not =
        "only " + std::to_string(xs.size()) +
        " levels start moving clearly (3 needed: levels of 10 % of the top speed or more)";
    return out;
  }
  // Least squares for t_on = delay + time_constant * x.
  const double n = static_cast<double>(xs.size());
  double sx = 0.0, st = 0.0, sxx = 0.0, sxt = 0.0;
  for (std::size_t k = 0; k < xs.size(); ++k) {
    sx += xs[k];
    st += ts[k];
    sxx += xs[k] * xs[k];
    sxt += xs[k] * ts[k];
  }
  const double det = n * sxx - sx * sx;
  char buf[200];
  if (!(det > 1e-9 * n * n)) {
    out.why_not = "the levels' onsets do not tell the delay from the lag (levels too alike)";
    return out;
  }
  out.time_constant_s = (n * sxt - sx * st) / det;
  out.delay_s = (st - out.time_constant_s * sx) / n;
  double sum_sq = 0.0;
  for (std::size_t k = 0; k < xs.size(); ++k) {
    const double e = ts[k] - (out.delay_s + out.time_constant_s * xs[k]);
    sum_sq += e * e;
  }
  out.residual_s = std::sqrt(sum_sq / n);
  const double allowed = std::max(kMinOnsetResidualS, max_residual * out.time_constant_s);
  if (!(out.time_constant_s > 0.0) || !(out.delay_s >= -kMinOnsetResidualS)) {
    std::snprintf(buf, sizeof buf,
                  "the onsets give no physical spool (delay %.3f s, time constant %.3f s)",
                  out.delay_s, out.time_constant_s);
    out.why_not = buf;
  } else if (out.residual_s > allowed) {
    std::snprintf(buf, sizeof buf,
                  "the onsets do not fit a delayed first-order spool (rms misfit %.1f ms, at most "
                  "%.1f ms)",
                  1e3 * out.residual_s, 1e3 * allowed);
    out.why_not = buf;
  } else {
    out.delay_s = std::max(out.delay_s, 0.0);
    out.identified = true;
  }
  return out;
}

std::string check_levels(const std::vector<double>& levels) {
  if (levels.empty()) return "no level given";
  for (std::size_t k = 0; k < levels.size(); ++k) {
    const double l = levels[k];
    if (!(l > 0.0 && l <= 1.0)) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "each level must be in (0, 1], got %g", l);
      return buf;
    }
    if (k > 0 && !(l > levels[k - 1])) return "the levels must be strictly ascending";
  }
  return {};
}

const char* to_string(SweepEnd end) {
  switch (end) {
    case SweepEnd::kComplete:
      return "complete";
    case SweepEnd::kStopRequested:
      return "stop requested";
    case SweepEnd::kMachineFault:
      return "machine fault";
    case SweepEnd::kNotPositioned:
      return "not positioned";
  }
  return "?";
}

SectionCalibration calibrate_section(const config::CraneConfig& config, int section,
                                     const CalibrationOptions& options,
                                     std::vector<SweepLogRow>* log) {
  const auto& model = config.model;
  check_section(model, section);
  const double period = 1.0 / config.control.rate_hz;
  sim_backend::SimSettings settings = sim_settings(config);
  settings.q_initial[section] = mid_stroke_q(model, section);

  // A simulated machine whose joint sensors are coarse, noisy or late is judged as a machine is.
  CalibrationOptions placed = options;
  if (!config.simulation.joints.exact())
    placed.settled_tolerance = options.machine_settled_tolerance;
  std::vector<SweepPoint> points;
  std::vector<SweepLogRow> own_log;  // the step responses, when the caller keeps no log
  if (log == nullptr) log = &own_log;
  const std::size_t first_row = log->size();
  for (double command : signed_commands(options.levels)) {
    sim_backend::SimBackend machine(model, settings);
    SweepTask task(config, section, {command}, placed, SweepTask::Mode::kPlaced, log);
    control::LoopOptions loop;
    loop.period_s = period;
    loop.max_cycles = task.level_cycles() + 1;  // a bound: the task finishes after its level
    loop.stop_at_end = false;  // one level of the sweep on the simulator: the next starts afresh
    control::run_control_loop(task, machine, loop);
    points.insert(points.end(), task.points().begin(), task.points().end());
  }
  SectionCalibration result = fit_section(section, std::move(points), placed);
  result.dynamics =
      identify_valve_dynamics(result.table, std::span(*log).subspan(first_row), section);
  return result;
}

MachineSweep calibrate_section_on_machine(const config::CraneConfig& config,
                                          valves::MachineInterface& machine, int section,
                                          const CalibrationOptions& options,
                                          const std::atomic<bool>* stop,
                                          std::vector<SweepLogRow>* log) {
  check_section(config.model, section);
  const double rate = config.control.rate_hz;
  const std::vector<double> commands = signed_commands(options.levels);
  std::vector<SweepLogRow> own_log;  // the step responses, when the caller keeps no log
  if (log == nullptr) log = &own_log;
  const std::size_t first_row = log->size();
  SweepTask task(config, section, commands, options, SweepTask::Mode::kMachine, log);
  control::LoopOptions loop;
  loop.period_s = 1.0 / rate;
  loop.realtime = machine.real_time();
  loop.stop = stop;
  loop.stop_cause = "operator stop";
  // A bound only: the task finishes the sweep itself, and each move has its own timeout.
  const double per_level_s = options.settle_s + options.measure_s + options.move.timeout_s + 1.0;
  loop.max_cycles = control::run_cycles(
      std::ceil((static_cast<double>(commands.size()) * per_level_s + 1.0) * rate),
      "the calibration sweep");
  const control::LoopSummary summary = control::run_control_loop(task, machine, loop);

  MachineSweep out;
  out.duration_s = summary.duration_s;
  out.wall_time_s = summary.wall_time_s;
  const auto& name = config.model.joints[static_cast<std::size_t>(section)].name;
  if (summary.machine_fault) {
    out.end = SweepEnd::kMachineFault;
    const std::string why = machine.fault_text();
    out.reason = "machine fault: " + (why.empty() ? std::string("(no reason given)") : why);
  } else if (summary.stop_requested) {
    out.end = SweepEnd::kStopRequested;
    out.reason = "stop requested during the sweep of " + name;
  } else if (task.not_positioned()) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "%s did not come to rest within %.3g %% of its stroke of mid-stroke in %.3g s "
                  "(the move uses the config's valve model: is dead_zone or the table right?)",
                  name.c_str(), options.move.tolerance * 100.0, options.move.timeout_s);
    out.reason = buf;
    out.end = SweepEnd::kNotPositioned;
  } else if (!task.finished()) {
    out.end = SweepEnd::kNotPositioned;
    out.reason = "the sweep of " + name + " ran out of time";
  }
  if (out.end == SweepEnd::kComplete) {
    out.section = fit_section(section, task.points(), options);
    out.section.dynamics =
        identify_valve_dynamics(out.section.table, std::span(*log).subspan(first_row), section);
  } else {
    out.section.section = section;  // the points so far, unfitted
    out.section.points = task.points();
  }
  return out;
}

dynamics::ValveTable fit_valve_table(const std::vector<SweepPoint>& points, double zero_speed_m_s) {
  // Pool adjacent violators: blocks of (mean velocity, weight), non-decreasing in the end.
  struct Block {
    double value;
    int weight;
    std::size_t first, last;  // indices into `used`
  };
  std::vector<SweepPoint> used;
  for (const auto& p : points) {
    if (p.valid) used.push_back(p);
  }
  std::vector<Block> blocks;
  for (std::size_t k = 0; k < used.size(); ++k) {
    blocks.push_back({used[k].velocity_m_s, 1, k, k});
    while (blocks.size() > 1 && blocks[blocks.size() - 2].value > blocks.back().value) {
      const Block b = blocks.back();
      blocks.pop_back();
      Block& a = blocks.back();
      a.value = (a.value * a.weight + b.value * b.weight) / (a.weight + b.weight);
      a.weight += b.weight;
      a.last = b.last;
    }
  }
  // One point per block (a pooled run becomes its mean command), tiny speeds are the dead band.
  std::vector<double> c, v;
  for (const auto& b : blocks) {
    const double value = std::abs(b.value) < zero_speed_m_s ? 0.0 : b.value;
    if (value == 0.0) {
      for (std::size_t k = b.first; k <= b.last; ++k) {
        c.push_back(used[k].command);
        v.push_back(0.0);
      }
      continue;
    }
    double sum = 0.0;
    for (std::size_t k = b.first; k <= b.last; ++k) sum += used[k].command;
    c.push_back(sum / static_cast<double>(b.last - b.first + 1));
    v.push_back(value);
  }
  // Dead-band edges: extrapolate the first moving segment on each side to zero velocity.
  dynamics::ValveTable t;
  const auto first_pos = static_cast<std::size_t>(std::upper_bound(v.begin(), v.end(), 0.0) -
                                                  v.begin());  // first moving out
  const auto first_zero = static_cast<std::size_t>(std::lower_bound(v.begin(), v.end(), 0.0) -
                                                   v.begin());  // first not moving in
  double edge_neg = 0.0, edge_pos = 0.0;
  const bool has_still = first_zero < first_pos;
  if (has_still) {
    edge_neg = c[first_zero];
    edge_pos = c[first_pos - 1];
    if (first_pos + 1 < v.size()) {
      const double e = c[first_pos] - v[first_pos] * (c[first_pos + 1] - c[first_pos]) /
                                          (v[first_pos + 1] - v[first_pos]);
      edge_pos = std::clamp(e, edge_pos, c[first_pos]);
    }
    if (first_zero >= 2) {
      const std::size_t k = first_zero - 1;  // last moving in
      const double e = c[k] + (0.0 - v[k]) * (c[k] - c[k - 1]) / (v[k] - v[k - 1]);
      edge_neg = std::clamp(e, c[k], edge_neg);
    }
  }
  for (std::size_t k = 0; k < first_zero; ++k) {
    t.command.push_back(c[k]);
    t.velocity_m_s.push_back(v[k]);
  }
  if (has_still) {
    t.command.push_back(edge_neg);
    t.velocity_m_s.push_back(0.0);
    if (edge_pos > edge_neg) {
      t.command.push_back(edge_pos);
      t.velocity_m_s.push_back(0.0);
    }
  }
  for (std::size_t k = first_pos; k < c.size(); ++k) {
    // An edge may coincide with the first moving level only if that level barely moves; keep the
    // commands strictly increasing.
    if (!t.command.empty() && !(c[k] > t.command.back())) continue;
    t.command.push_back(c[k]);
    t.velocity_m_s.push_back(v[k]);
  }
  return t;
}

void apply_dynamics(const ValveDynamics& found, dynamics::ValveTable& table) {
  if (!found.identified) return;
  table.time_constant_s = kLeadTimeConstantShare * found.time_constant_s;
  table.delay_s = found.delay_s;
}

std::string valve_tables_yaml(const dynamics::CraneModel& model,
                              const std::vector<SectionCalibration>& sections,
                              const std::string& comment) {
  std::string out = "    # " + comment + "\n    tables:\n";
  for (const auto& s : sections) {
    out += "      " + model.joints[static_cast<std::size_t>(s.section)].name + ":\n";
    out += "        command: " + format_list(s.table.command) + ", measured\n";
    out += "        velocity: " + format_list(s.table.velocity_m_s) + " m/s, measured\n";
    if (s.dynamics.identified) {
      dynamics::ValveTable t;
      apply_dynamics(s.dynamics, t);
      char buf[320];
      std::snprintf(
          buf, sizeof buf,
          "        # spool: delay %.4f s, time constant %.4f s measured (onsets' rms misfit "
          "%.1f ms); the lead plans on %.0f %% of it\n"
          "        time_constant: %.4f s, measured\n        delay: %.4f s, measured\n",
          s.dynamics.delay_s, s.dynamics.time_constant_s, 1e3 * s.dynamics.residual_s,
          100.0 * kLeadTimeConstantShare, t.time_constant_s, t.delay_s);
      out += buf;
    }
  }
  return out;
}

void write_sweep_log(std::ostream& out, const dynamics::CraneModel& model,
                     const std::vector<SweepLogRow>& rows) {
  out << "section,joint,command,t,cylinder_position,cylinder_velocity,measuring\n";
  char buf[160];
  for (const auto& r : rows) {
    std::snprintf(buf, sizeof buf, "%d,%s,%.4f,%.3f,%.6f,%.6f,%d\n", r.section,
                  model.joints[static_cast<std::size_t>(r.section)].name.c_str(), r.command, r.t_s,
                  r.cylinder_m, r.cylinder_velocity_m_s, r.measuring ? 1 : 0);
    out << buf;
  }
}

}  // namespace craneassist::offline
