#include "craneassist/offline/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <stdexcept>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/valve_table.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

namespace craneassist::offline {
namespace {

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

// The calibration's cycle task: one section's spool held at a level, every other valve neutral.
class HoldValves final : public control::CycleTask {
 public:
  HoldValves(int dof, int section, double level) : section_(section), level_(level) {
    spool_.setZero(dof);
    spool_[section] = level;
  }
  void start(const valves::MachineState&, double) override {}
  control::CycleStatus step(const control::CycleTime& time, const valves::MachineState& state,
                            const char*, valves::ValveCommand& command,
                            control::LogRow& row) noexcept override {
    command.spool = spool_;
    row.t = time.t_s;
    if (state.valid) row.q[static_cast<std::size_t>(section_)] = state.q[section_];
    row.spool[static_cast<std::size_t>(section_)] = level_;
    row.set_pump(state.pump);
    return control::CycleStatus::kRunning;
  }

 private:
  int section_;
  double level_;
  dynamics::JointVector spool_;
};

// Measures the steady cylinder velocity of one level: the mean over the window after the settle
// time, invalid when the two halves of the window differ or the stroke comes near an end stop.
class LevelProbe final : public control::CycleObserver {
 public:
  LevelProbe(const dynamics::Cylinder& cyl, int section, double command, int settle_cycles,
             int measure_cycles, double period_s, double c_lo, double c_hi, double tolerance,
             std::vector<SweepLogRow>* log)
      : cyl_(cyl),
        section_(section),
        settle_(settle_cycles),
        measure_(measure_cycles),
        half_(settle_cycles + measure_cycles / 2),
        period_s_(period_s),
        c_lo_(c_lo),
        c_hi_(c_hi),
        tolerance_(tolerance),
        log_(log),
        point_{command, 0.0, true} {
    if (log_ != nullptr)
      log_->reserve(log_->size() + static_cast<std::size_t>(settle_ + measure_ + 1));
  }

  void on_cycle(const control::CycleRecord& c) noexcept override {
    const long k = c.time.k;
    const double q = c.state.q[section_];
    const double length = dynamics::cylinder_length(cyl_, q);
    const bool measuring = k >= settle_;
    if (k == settle_) c_start_ = length;
    if (k == half_) c_half_ = length;
    if (measuring && (length < c_lo_ || length > c_hi_)) point_.valid = false;
    if (k == settle_ + measure_) {
      point_.velocity_m_s = (length - c_start_) / (measure_ * period_s_);
      const double v1 = (c_half_ - c_start_) / ((half_ - settle_) * period_s_);
      const double v2 = (length - c_half_) / ((settle_ + measure_ - half_) * period_s_);
      const double scale = std::max(std::abs(point_.velocity_m_s), 1e-3 * cyl_.v_max_m_s);
      if (std::abs(v2 - v1) > tolerance_ * scale) point_.valid = false;
    }
    if (log_ != nullptr) {
      log_->push_back({section_, point_.command, static_cast<double>(k) * period_s_, length,
                       dynamics::cylinder_arm(cyl_, q) * c.state.qdot[section_], measuring});
    }
  }
  const SweepPoint& point() const { return point_; }

 private:
  const dynamics::Cylinder& cyl_;
  int section_;
  int settle_, measure_, half_;
  double period_s_, c_lo_, c_hi_, tolerance_;
  std::vector<SweepLogRow>* log_;
  SweepPoint point_;
  double c_start_ = 0.0, c_half_ = 0.0;
};

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

SectionCalibration calibrate_section(const config::CraneConfig& config, int section,
                                     const CalibrationOptions& options,
                                     std::vector<SweepLogRow>* log) {
  const auto& model = config.model;
  if (section < 0 || section >= model.dof()) throw std::invalid_argument("no such section");
  const auto i = static_cast<std::size_t>(section);
  const auto& joint = model.joints[i];
  const auto& cyl = model.cylinders[i];
  const double period = 1.0 / config.control.rate_hz;
  const int settle_cycles = static_cast<int>(std::lround(options.settle_s / period));
  const int measure_cycles = std::max(1, static_cast<int>(std::lround(options.measure_s / period)));
  const double c_a = dynamics::cylinder_length(cyl, joint.q_min);
  const double c_b = dynamics::cylinder_length(cyl, joint.q_max);
  const double margin = options.end_margin * std::abs(c_b - c_a);
  const double c_lo = std::min(c_a, c_b) + margin, c_hi = std::max(c_a, c_b) - margin;

  sim_backend::SimSettings settings{config.simulation.step_s, config.simulation.q_initial};
  settings.q_initial[section] = mid_stroke_q(model, section);

  SectionCalibration result;
  result.section = section;
  result.points.push_back({0.0, 0.0, true});
  for (double level : options.levels) {
    for (double sign : {-1.0, 1.0}) {
      sim_backend::SimBackend machine(model, settings);
      HoldValves task(model.dof(), section, sign * level);
      LevelProbe probe(cyl, section, sign * level, settle_cycles, measure_cycles, period, c_lo,
                       c_hi, options.settled_tolerance, log);
      control::LoopOptions loop;
      loop.period_s = period;
      loop.max_cycles = settle_cycles + measure_cycles + 1;
      loop.stop_at_end = false;  // one level of the sweep on the simulator: the next continues
      loop.observers = {&probe};
      control::run_control_loop(task, machine, loop);
      const SweepPoint point = probe.point();
      result.points.push_back(point);
    }
  }
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

std::string valve_tables_yaml(const dynamics::CraneModel& model,
                              const std::vector<SectionCalibration>& sections,
                              const std::string& comment) {
  std::string out = "    # " + comment + "\n    tables:\n";
  for (const auto& s : sections) {
    out += "      " + model.joints[static_cast<std::size_t>(s.section)].name + ":\n";
    out += "        command: " + format_list(s.table.command) + ", measured\n";
    out += "        velocity: " + format_list(s.table.velocity_m_s) + " m/s, measured\n";
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
