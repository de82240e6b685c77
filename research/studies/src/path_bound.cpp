#include "craneassist/studies/path_bound.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/control/controller.hpp"
#include "craneassist/control/replay_runner.hpp"
#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/dynamics/inverse_kinematics.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/scaling/scaling_filter.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

namespace craneassist::studies {
namespace {

constexpr double kMinPartLength = 0.05;  // m: shorter moving parts of a replay are left out
constexpr double kDriveSpeed = 3.0;      // m/s: the stick's request when driving a path
constexpr double kLookAheadTime = 0.5;   // s: the stick points at the path this far ahead
constexpr double kMinLookAhead = 0.02;   // m
constexpr double kDriveStep = 0.005;     // m: the tip path's points for the drive

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kCurvatureSpan = 0.05;  // m: f'' and the tip's curvature over +-5 cm

// f' by central differences of the joint samples (one-sided at the ends), f'' by central
// differences over +-kCurvatureSpan (the samples interpolate the reference linearly between
// control cycles, which move the tip up to 2 cm: closer differences see those kinks), and the
// cylinder arms at each sample.
void finish_geometry(const dynamics::CraneModel& model, std::vector<paths::PathSample>& s) {
  const std::size_t n = s.size();
  const int dof = model.dof();
  const double ds =
      (s.back().s - s.front().s) / static_cast<double>(std::max<std::size_t>(n - 1, 1));
  const auto span = static_cast<std::size_t>(std::max(1.0, std::round(kCurvatureSpan / ds)));
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 == n ? n - 1 : k + 1;
    auto& g = s[k].geometry;
    g.f1 = (s[b].q - s[a].q) / (s[b].s - s[a].s);
    const std::size_t m = std::min({span, k, n - 1 - k});  // narrower near the ends
    if (m > 0) {
      const double h1 = s[k].s - s[k - m].s, h2 = s[k + m].s - s[k].s;
      g.f2 = 2.0 * ((s[k + m].q - s[k].q) / h2 - (s[k].q - s[k - m].q) / h1) / (h1 + h2);
    } else {
      g.f2 = dynamics::JointVector::Zero(dof);
    }
    dynamics::cylinder_arms(model, s[k].q, g.dc_dq);
    g.d2c_dq2.resize(dof);
    for (int i = 0; i < dof; ++i) {
      g.d2c_dq2[i] =
          dynamics::cylinder_arm_slope(model.cylinders[static_cast<std::size_t>(i)], s[k].q[i]);
    }
  }
  if (n >= 3) {  // the end samples' f'' from their neighbours
    s.front().geometry.f2 = s[1].geometry.f2;
    s.back().geometry.f2 = s[n - 2].geometry.f2;
  }
}

// The turning limit of the online scaling as a speed cap: the tip's normal acceleration
// sdot^2 kappa stays within direction_change_acceleration, kappa the curvature of the samples'
// tip path (over +-kCurvatureSpan).
void cap_by_curvature(const config::CraneConfig& cfg, std::vector<paths::PathSample>& s) {
  const std::size_t n = s.size();
  if (n < 3) return;
  dynamics::KinematicsData kin;
  std::vector<Eigen::Vector3d> tip(n);
  for (std::size_t k = 0; k < n; ++k) tip[k] = dynamics::tip_position(cfg.model, kin, s[k].q);
  const double ds = (s.back().s - s.front().s) / static_cast<double>(n - 1);
  const auto span = static_cast<std::size_t>(std::max(1.0, std::round(kCurvatureSpan / ds)));
  for (std::size_t k = 1; k + 1 < n; ++k) {
    const std::size_t m = std::min({span, k, n - 1 - k});
    const double h = 0.5 * (s[k + m].s - s[k - m].s);
    const double curvature = (tip[k + m] - 2.0 * tip[k] + tip[k - m]).norm() / (h * h);
    const double turning =
        curvature > 0.0 ? std::sqrt(cfg.scaling.direction_change_acceleration_m_s2 / curvature)
                        : kInfinity;
    if (turning < s[k].sdot_cap) {
      s[k].sdot_cap = turning;
      s[k].cap_name = "turning";
    }
  }
}

// Points of a polyline resampled every ds along its arc length (the last point kept).
std::vector<Eigen::Vector3d> resample(const std::vector<Eigen::Vector3d>& points, double ds) {
  std::vector<Eigen::Vector3d> out{points.front()};
  double carried = 0.0;  // arc length since the last output point
  for (std::size_t i = 1; i < points.size(); ++i) {
    const Eigen::Vector3d a = points[i - 1], d = points[i] - a;
    const double len = d.norm();
    double used = 0.0;
    while (carried + (len - used) >= ds) {
      used += ds - carried;
      carried = 0.0;
      out.push_back(a + d * (used / len));
    }
    carried += len - used;
  }
  if (carried > 0.25 * ds) out.push_back(points.back());
  return out;
}

struct DriveCycle {
  double s, sdot;
  dynamics::JointVector q;
};

struct DriveResult {
  std::vector<DriveCycle> cycles;  // the reference at each cycle, s its tip's arc length
  double time_s = 0.0;
  bool arrived = false;
  double speed_share = 0.0, acceleration_share = 0.0, power_share = 0.0;
  double overshoot_m = 0.0;  // where the reference stopped beyond the path's end (< 0: short)
  double deviation_m = 0.0;  // the reference tip's largest distance from the path
};

// The controller drives the tip path `points` (every kDriveStep) from q: the stick towards the
// path's point kLookAheadTime ahead of the reference tip's place on it (pure pursuit: the
// reference turns with bounded normal acceleration, so it must be steered ahead of a bend), at
// bend_speed there,
// released when a stop from the present speed and acceleration needs the rest of the path less
// early_m (or at its end). Its reference is the joint path; a machine that follows it exactly,
// one valve delay (transport delay plus spool lag) late, as the controller expects.
DriveResult drive_path(const config::CraneConfig& cfg, const dynamics::JointVector& q,
                       const std::vector<Eigen::Vector3d>& points,
                       const std::vector<double>& bend_speed, double early_m, double time_limit_s) {
  const auto& model = cfg.model;
  const double length = kDriveStep * static_cast<double>(points.size() - 1);
  auto drive_cfg = cfg;
  drive_cfg.simulation.q_initial = q;
  // The drive has no pressures to weigh with: the controller is told the payload.
  control::Controller controller(drive_cfg,
                                 {.mode = control::ScalingMode::kFull, .payload_known = true});
  valves::MachineState state;
  state.q = q;
  state.qdot = dynamics::JointVector::Zero(4);
  state.load_pressure_pa = dynamics::JointVector::Zero(4);
  state.valid = true;
  controller.reset(state);
  control::ControllerOutput ctl;
  dynamics::KinematicsData kin;
  const double period = controller.period_s();
  const auto lag = static_cast<std::size_t>(
      std::lround((model.valves.delay_s + model.valves.time_constant_s) / period));
  std::vector<dynamics::JointVector> history(std::max<std::size_t>(lag, 1), q);
  DriveResult out;
  out.cycles.push_back({0.0, 0.0, q});
  std::size_t cycle = 0, near = 0;  // near: the path point nearest the reference tip
  bool released = false;
  dynamics::JointVector arms(4), v_cyl_last = dynamics::JointVector::Zero(4);
  double t = 0.0;
  for (; t < time_limit_s; t += period) {
    const Eigen::Vector3d tip = dynamics::tip_position(model, kin, cycle ? ctl.q_ref : q);
    for (std::size_t k = near; k < std::min(points.size(), near + 400); ++k) {
      if ((points[k] - tip).squaredNorm() < (points[near] - tip).squaredNorm()) near = k;
    }
    const double s = kDriveStep * static_cast<double>(near);
    out.deviation_m = std::max(out.deviation_m, (points[near] - tip).norm());
    const std::size_t a = near == 0 ? 0 : near - 1, b = std::min(near + 1, points.size() - 1);
    Eigen::Vector3d tangent = (points[b] - points[a]).normalized();
    const auto ahead =
        std::min(points.size() - 1,
                 near + static_cast<std::size_t>(
                            std::max(kMinLookAhead, kLookAheadTime * ctl.sdot) / kDriveStep));
    if (ahead > near) tangent = (points[ahead] - tip).normalized();
    const double braking =
        scaling::braking_distance(ctl.sdot, released ? 0.0 : ctl.sddot,
                                  cfg.scaling.deceleration_max_m_s2, cfg.scaling.jerk_max_m_s3);
    released = released || near + 1 == points.size() || braking + early_m >= length - s;
    const Eigen::Vector3d command =
        released ? Eigen::Vector3d::Zero() : Eigen::Vector3d(tangent * bend_speed[near]);
    controller.update(state, command, ctl);
    history[cycle % history.size()] = ctl.q_ref;
    state.q = history[(cycle + 1) % history.size()];
    ++cycle;
    out.cycles.push_back({ctl.s, ctl.sdot, ctl.q_ref});
    dynamics::cylinder_arms(model, ctl.q_ref, arms);
    const dynamics::JointVector v_cyl = arms.cwiseProduct(ctl.qdot_ref);
    for (int j = 0; j < 4; ++j) {
      const auto& cyl = model.cylinders[static_cast<std::size_t>(j)];
      out.speed_share = std::max(out.speed_share, std::abs(v_cyl[j]) / cyl.v_max_m_s);
      out.acceleration_share = std::max(
          out.acceleration_share, std::abs(v_cyl[j] - v_cyl_last[j]) / period / cyl.a_max_m_s2);
    }
    v_cyl_last = v_cyl;
    out.power_share = std::max(out.power_share, ctl.ref_power_w / model.pump.prime_mover_power_w);
    if (released && ctl.sdot == 0.0) break;
  }
  out.time_s = t;
  out.arrived = t < time_limit_s;
  const Eigen::Vector3d end_tangent = (points.back() - points[points.size() - 2]).normalized();
  out.overshoot_m =
      (dynamics::tip_position(model, kin, ctl.q_ref) - points.back()).dot(end_tangent);
  return out;
}

}  // namespace

JointPath joint_path_for(const config::CraneConfig& cfg, const input::PrescribedPath& path,
                         const JointPathOptions& options) {
  const auto& model = cfg.model;
  if (!dynamics::is_loader_structure(model)) {
    throw std::runtime_error("the bound needs a loader crane (slew, lift, tilt, extension)");
  }
  // The tip path by its arc length.
  std::vector<Eigen::Vector3d> fine;
  const double dt = std::min(1e-3, path.duration_s() / 1000.0);
  for (double t = path.start_time_s(); t <= path.end_time_s() + 0.5 * dt; t += dt) {
    fine.push_back(path.at(std::min(t, path.end_time_s())).p_m);
  }
  const auto points = resample(fine, kDriveStep);
  if (points.size() < 3) throw std::runtime_error("the path is shorter than three samples");
  // The speed each point allows with the tip's normal acceleration at its bound (the turning
  // limit of the online scaling), and the speed from which the drive can still slow down to
  // every later one: an operator eases off before a bend.
  const double normal = cfg.scaling.direction_change_acceleration_m_s2;
  const double ease = 0.5 * cfg.scaling.deceleration_max_m_s2;
  std::vector<double> bend_speed(points.size(), kDriveSpeed);
  for (std::size_t k = 1; k + 1 < points.size(); ++k) {
    const double curvature =
        (points[k + 1] - 2.0 * points[k] + points[k - 1]).norm() / (kDriveStep * kDriveStep);
    if (curvature > 0.0) bend_speed[k] = std::min(kDriveSpeed, std::sqrt(normal / curvature));
  }
  for (std::size_t k = points.size() - 1; k-- > 0;) {
    bend_speed[k] = std::min(
        bend_speed[k], std::sqrt(bend_speed[k + 1] * bend_speed[k + 1] + 2.0 * ease * kDriveStep));
  }

  // Start configuration: the feasible extensions at the start point.
  JointPath out;
  dynamics::JointVector q(4);
  double lo = 0.0, hi = -1.0;
  const auto& ext = model.joints[3];
  for (int k = 0; k <= 740; ++k) {
    const double q4 = ext.q_min + (ext.q_max - ext.q_min) * k / 740.0;
    if (dynamics::solve_given_extension(model, points.front(), q4, q) == dynamics::IkStatus::kOk) {
      if (hi < lo) lo = q4;
      hi = q4;
    }
  }
  if (hi < lo) throw std::runtime_error("the path's start is out of reach of the crane");
  out.start_extension_m = options.start == StartExtension::kShortest ? lo : 0.5 * (lo + hi);
  dynamics::solve_given_extension(model, points.front(), out.start_extension_m, q);

  // The controller drives the path (drive_path); the release point is moved until the
  // reference stops within a centimetre of the path's end (a stop at the scaler's own
  // deceleration bounds runs longer than one at the path deceleration alone).
  DriveResult drive;
  double early_m = 0.0;
  for (int attempt = 0; attempt < 6; ++attempt) {
    drive = drive_path(cfg, q, points, bend_speed, early_m, 20.0 * path.duration_s() + 30.0);
    if (!drive.arrived || std::abs(drive.overshoot_m) < 0.01) break;
    early_m = std::max(0.0, early_m + drive.overshoot_m);
  }
  out.online_time_s = drive.time_s;
  out.online_arrived = drive.arrived;
  out.online_speed_share = drive.speed_share;
  out.online_acceleration_share = drive.acceleration_share;
  out.online_deviation_m = drive.deviation_m;
  out.online_power_share = drive.power_share;
  const auto& cycles = drive.cycles;

  // The joint path: the reference at each cycle, resampled uniformly in s.
  std::size_t i = 0;
  for (double s = 0.0; s <= cycles.back().s + 1e-12; s += options.ds_m) {
    while (i + 1 < cycles.size() && cycles[i + 1].s < s) ++i;
    const auto& c0 = cycles[i];
    const auto& c1 = cycles[std::min(i + 1, cycles.size() - 1)];
    const double w = c1.s > c0.s ? std::clamp((s - c0.s) / (c1.s - c0.s), 0.0, 1.0) : 0.0;
    paths::PathSample sample;
    sample.s = s;
    sample.q = (1 - w) * c0.q + w * c1.q;
    out.samples.push_back(sample);
    out.online_sdot.push_back((1 - w) * c0.sdot + w * c1.sdot);
  }
  if (out.samples.size() < 3) throw std::runtime_error("the drive did not move along the path");
  finish_geometry(model, out.samples);
  cap_by_curvature(cfg, out.samples);
  return out;
}

namespace {

// Copies the reference and the command of every cycle (the run is not real time: a vector is
// fine here).
class ReferenceRecorder : public control::CycleObserver {
 public:
  bool reads_polytope() const noexcept override { return false; }
  void on_cycle(const control::CycleRecord& cycle) noexcept override {
    const control::LogRow& row = cycle.row;
    Row r;
    r.t = row.t;
    r.s = row.s;
    r.sdot = row.sdot;
    r.cmd = std::hypot(row.cmd[0], row.cmd[1], row.cmd[2]);
    r.q = row.q_ref;
    rows.push_back(r);
  }
  struct Row {
    double t, s, sdot, cmd;
    std::array<double, control::LogRow::kMaxJoints> q;
  };
  std::vector<Row> rows;
};

}  // namespace

std::vector<JointPath> joint_paths_from_replay(const config::CraneConfig& cfg,
                                               const input::Replay& replay, double ds_m,
                                               std::vector<double>& online_time_s) {
  const auto& model = cfg.model;
  const int dof = model.dof();
  ReferenceRecorder recorder;
  recorder.rows.reserve(
      static_cast<std::size_t>((replay.end_time_s() + 2.0) * cfg.control.rate_hz) + 16);
  sim_backend::SimBackend machine(model, offline::sim_settings(cfg));
  control::RunOptions options;
  options.observers.push_back(&recorder);
  control::run_replay(cfg, replay, machine, options, nullptr);

  std::vector<JointPath> parts;
  online_time_s.clear();
  const auto& rows = recorder.rows;
  std::size_t k = 0;
  while (k < rows.size()) {
    // A moving part: from leaving rest to the next rest.
    while (k < rows.size() && rows[k].sdot == 0.0) ++k;
    if (k >= rows.size()) break;
    const std::size_t first = k - (k > 0 ? 1 : 0);
    while (k < rows.size() && rows[k].sdot > 0.0) ++k;
    const std::size_t last = std::min(k, rows.size() - 1);
    const double length = rows[last].s - rows[first].s;
    if (length < kMinPartLength) continue;
    JointPath part;
    // Resample the reference at uniform s (linear between cycles).
    std::size_t i = first;
    for (double s = rows[first].s; s <= rows[last].s + 1e-12; s += ds_m) {
      while (i + 1 < last && rows[i + 1].s < s) ++i;
      const auto& a = rows[i];
      const auto& b = rows[std::min(i + 1, last)];
      const double w = b.s > a.s ? std::clamp((s - a.s) / (b.s - a.s), 0.0, 1.0) : 0.0;
      paths::PathSample sample;
      sample.s = s - rows[first].s;
      sample.q.resize(dof);
      for (int j = 0; j < dof; ++j)
        sample.q[j] =
            (1 - w) * a.q[static_cast<std::size_t>(j)] + w * b.q[static_cast<std::size_t>(j)];
      // The operator's request where the reference passed (never below the speed it reached).
      sample.sdot_cap = std::max({a.cmd, b.cmd, (1 - w) * a.sdot + w * b.sdot});
      sample.cap_name = "operator request";
      part.samples.push_back(sample);
      part.online_sdot.push_back((1 - w) * a.sdot + w * b.sdot);
    }
    if (part.samples.size() < 3) continue;
    finish_geometry(model, part.samples);
    cap_by_curvature(cfg, part.samples);
    parts.push_back(std::move(part));
    online_time_s.push_back(rows[last].t - rows[first].t);
  }
  return parts;
}

BoundFigures bound_figures(const config::CraneConfig& cfg, const JointPath& path) {
  dynamics::RigidBodyTerms terms(cfg.model);
  BoundFigures out;
  out.length_m = path.samples.back().s - path.samples.front().s;
  paths::TimeOptimalSettings settings;
  settings.acceleration_max = cfg.scaling.acceleration_max_m_s2;
  settings.deceleration_max = cfg.scaling.deceleration_max_m_s2;
  settings.flow_reserve = cfg.control.flow_reserve;
  settings.power_bound = cfg.scaling.power_bound;
  settings.power_reserve = cfg.scaling.power_reserve;
  out.bound = paths::time_optimal_profile(cfg.model, terms, path.samples, settings);
  return out;
}

}  // namespace craneassist::studies
