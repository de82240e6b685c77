#include "craneassist/studies/mobile_follow.hpp"

#include <cmath>
#include <numbers>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "craneassist/control/controller.hpp"
#include "craneassist/dynamics/inverse_kinematics.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/paths/path_scaler.hpp"
#include "craneassist/sim_backend/mobile_crane_backend.hpp"

namespace craneassist::studies {
namespace {

// The errors below which the initial pose error counts as corrected.
constexpr double kSettledErrorM = 0.2;
// The deceleration the arm's P term plans with when it closes a large error, m/s^2 (below the
// K70M's path deceleration bound, 2 m/s^2, so the jerk-limited reference can follow it).
constexpr double kArmStopAcceleration = 0.5;

struct ToolTarget {
  const paths::CompositeBezierPath& path;
  const config::BaseConfig& base;
  const FollowOptions& options;

  // The desired tool position in the world at s.
  Eigen::Vector3d world(double s) const {
    paths::CompositeBezierPath::Point pt;
    path.evaluate(s, pt);
    const double z =
        base.following.tool_height_m +
        options.height_amplitude_m * std::sin(2.0 * std::numbers::pi * options.height_cycles * s);
    return {pt.p.x(), pt.p.y(), z};
  }
};

// World point -> crane task frame (x forward, y up, z lateral for the K70M), for the platform
// at `pose`.
Eigen::Vector3d task_from_world(const config::CraneConfig& crane,
                                const dynamics::MobileBaseModel& base,
                                const dynamics::BasePose& pose, const Eigen::Vector3d& w) {
  return crane.model.task_from_base * dynamics::crane_base_from_world(base, pose, w);
}

Eigen::Vector3d world_from_task(const config::CraneConfig& crane,
                                const dynamics::MobileBaseModel& base,
                                const dynamics::BasePose& pose, const Eigen::Vector3d& t) {
  return dynamics::world_from_crane_base(base, pose, crane.model.task_from_base.transpose() * t);
}

// A crane pose that puts the tip at `tip` (task frame): the extension nearest the config's
// initial one for which every joint is within its range.
dynamics::JointVector initial_crane_pose(const config::CraneConfig& crane,
                                         const Eigen::Vector3d& tip) {
  const dynamics::CraneModel& model = crane.model;
  if (!dynamics::is_loader_structure(model)) {
    throw std::invalid_argument(
        "tool path following needs a loader crane (slew, lift, tilt, "
        "extension)");
  }
  const auto& ext = model.joints[3];
  const double q4_initial = crane.simulation.q_initial[3];
  dynamics::JointVector best;
  double best_gap = 1e300;
  for (int k = 0; k <= 100; ++k) {
    const double q4 = ext.q_min + (ext.q_max - ext.q_min) * k / 100.0;
    dynamics::JointVector q;
    if (dynamics::solve_given_extension(model, tip, q4, q) != dynamics::IkStatus::kOk) continue;
    if (std::abs(q4 - q4_initial) < best_gap) {
      best_gap = std::abs(q4 - q4_initial);
      best = q;
    }
  }
  if (best.size() == 0) {
    std::ostringstream why;
    why << "the crane cannot reach the tool's start (" << tip.transpose()
        << " m in its frame) with its joints in range";
    throw std::invalid_argument(why.str());
  }
  return best;
}

}  // namespace

FollowResult run_follow(const config::CraneConfig& crane, const config::BaseConfig& base,
                        const paths::CompositeBezierPath& path, const FollowOptions& options) {
  const dynamics::MobileBaseModel& bm = base.model;
  const double period = 1.0 / crane.control.rate_hz;
  paths::BaseFollowerConfig fc;
  fc.k1_1_m = base.following.k1_1_m;
  fc.k2 = base.following.k2;
  fc.k3_1_m = base.following.k3_1_m;
  fc.epsilon_m = base.following.epsilon_m;
  fc.tool_offset_m = base.following.tool_offset_m;
  fc.period_s = period;
  paths::BasePathFollower follower(bm, path, fc);
  follower.set_arm_shares_pump(base.arm_shares_pump);
  const paths::OffsetPathCheck check = paths::check_offset_path(path, fc.tool_offset_m);
  if (check.max_curvature_1_m > dynamics::max_curvature_1_m(bm) * (1.0 + 1e-9)) {
    std::ostringstream why;
    why << "the platform's path turns on a radius of " << 1.0 / check.max_curvature_1_m
        << " m near s = " << check.max_curvature_s << ", tighter than the steering allows ("
        << 1.0 / dynamics::max_curvature_1_m(bm) << " m at the chassis centre)";
    throw std::invalid_argument(why.str());
  }

  const ToolTarget target{path, base, options};
  paths::OffsetReference r0;
  paths::offset_reference(path, fc.tool_offset_m, 0.0, r0);
  const dynamics::BasePose reference0{r0.platform.x(), r0.platform.y(), r0.phi_rad};
  const double c0 = std::cos(r0.phi_rad), s0 = std::sin(r0.phi_rad);
  const dynamics::BasePose start{
      r0.platform.x() + c0 * options.start_along_m - s0 * options.start_left_m,
      r0.platform.y() + s0 * options.start_along_m + c0 * options.start_left_m,
      r0.phi_rad + options.start_heading_rad};
  // The arm starts holding the tool where it belongs relative to the platform's reference:
  // the tool error at the start is the platform's pose error.
  const Eigen::Vector3d tip0 = task_from_world(crane, bm, reference0, target.world(0.0));
  sim_backend::SimSettings settings = offline::sim_settings(crane);
  settings.q_initial = initial_crane_pose(crane, tip0);

  // The crane on the base; with a shared pump the crane gets what the motors leave each step.
  sim_backend::MobileCraneBackend machine(crane.model, settings, bm, start, base.shared_with_crane);
  // Paper 003's study: the controller is told the payload, as the paper's was.
  control::Controller controller(crane, {.payload_known = true});
  valves::MachineState state;
  machine.read(state);
  controller.reset(state);

  FollowResult result;
  FollowSummary& sum = result.summary;
  sum.path_length_m = path.length_m();
  const long max_cycles = static_cast<long>(std::ceil(options.max_duration_s / period));
  result.rows.reserve(static_cast<std::size_t>(std::min(max_cycles, 200000L)) + 1);
  dynamics::KinematicsData kin;
  control::ControllerOutput out;
  out.q_ref = state.q;
  paths::BaseFollowerOutput fout;
  Eigen::Vector3d previous_target = Eigen::Vector3d::Constant(std::nan(""));
  const double alpha = period / (base.following.tool_error_filter_s + period);
  double error_filtered = -1.0;
  double sum_sq = 0.0, sum_sq_settled = 0.0;
  long settled_cycles = 0;
  double finished_at = -1.0;
  Eigen::Vector2d last_xy(start.x_m, start.y_m);

  for (long k = 0; k < max_cycles; ++k) {
    const double t = static_cast<double>(k) * period;
    machine.read(state);
    const sim_backend::MobileBaseState& ps = machine.base().state();
    const dynamics::BasePose pose = ps.pose;

    // The tool error: the target at the present s against the measured tip, in the platform's
    // frame (eq. 17's |e|), filtered.
    const Eigen::Vector3d tip = dynamics::tip_position(crane.model, kin, state.q);
    const Eigen::Vector3d wanted = task_from_world(crane, bm, pose, target.world(follower.s()));
    const double error = (wanted - tip).norm();
    error_filtered =
        error_filtered < 0.0 ? error : error_filtered + alpha * (error - error_filtered);
    const double delta = options.error_scaling ? scaling::tracking_factor(
                                                     error_filtered, base.following.tool_error_ok_m)
                                               : 1.0;

    // The platform (eqs. 10-18).
    paths::BaseFollowerInput in;
    in.pose = pose;
    in.tracking_factor = delta;
    in.arm_flow_m3_s = state.pump.flow_m3_s;
    follower.update(in, fout);

    // The arm: the tool point at the new s, relative to the measured platform, through the
    // crane's controller: its motion plus a P term on the reference tip's error.
    const Eigen::Vector3d goal = task_from_world(crane, bm, pose, target.world(fout.s));
    const Eigen::Vector3d feed_forward = std::isnan(previous_target.x())
                                             ? Eigen::Vector3d::Zero()
                                             : Eigen::Vector3d((goal - previous_target) / period);
    previous_target = goal;
    const Eigen::Vector3d ref_tip = dynamics::tip_position(crane.model, kin, out.q_ref);
    // The P term no faster than lets the reference stop at the goal at kArmStopAcceleration
    // (sqrt(2 a |e|)): a large error (the start) is closed without overshooting it.
    const Eigen::Vector3d gap = goal - ref_tip;
    const double distance = gap.norm();
    double p_speed = base.following.arm_position_gain_1_s * distance;
    p_speed = std::min(p_speed, std::sqrt(2.0 * kArmStopAcceleration * distance));
    const Eigen::Vector3d command =
        feed_forward +
        (distance > 0.0 ? Eigen::Vector3d(gap * (p_speed / distance)) : Eigen::Vector3d::Zero());
    controller.update(state, command, out);
    valves::ValveCommand to_machine = out.valves;
    to_machine.drive_v_m_s = fout.v_m_s;
    to_machine.drive_omega_rad_s = fout.omega_rad_s;
    machine.write(to_machine);

    FollowRow row;
    row.t = t;
    row.s = fout.s;
    row.sdot = fout.sdot;
    row.x = pose.x_m;
    row.y = pose.y_m;
    row.phi = pose.phi_rad;
    row.x_d = fout.reference.platform.x();
    row.y_d = fout.reference.platform.y();
    row.phi_d = fout.reference.phi_rad;
    row.e_x = fout.e_x_m;
    row.e_y = fout.e_y_m;
    row.e_phi = fout.e_phi_rad;
    row.v_cmd = fout.v_m_s;
    row.omega_cmd = fout.omega_rad_s;
    row.v = ps.velocity.v_m_s;
    row.omega = ps.velocity.omega_rad_s;
    row.v_max = fout.v_max_m_s;
    for (std::size_t i = 0; i < 4; ++i) {
      row.flow[i] = ps.wheels.flow_m3_s[i];
      row.steer[i] = ps.wheels.steer_rad[i];
    }
    row.flow_sum = ps.wheels.flow_sum_m3_s;
    row.flow_max = fout.flow_budget_m3_s;
    const Eigen::Vector3d tool_world = world_from_task(crane, bm, pose, tip);
    const Eigen::Vector3d tool_wanted = world_from_task(crane, bm, pose, wanted);
    for (int a = 0; a < 3; ++a) {
      row.tool[a] = tool_world[a];
      row.tool_d[a] = tool_wanted[a];
    }
    row.tool_error = error;
    row.tool_error_filtered = error_filtered;
    row.delta = delta;
    for (int i = 0; i < std::min<int>(4, static_cast<int>(state.q.size())); ++i)
      row.q[i] = state.q[i];
    row.arm_flow = state.pump.flow_m3_s;
    row.arm_flow_max = machine.crane().pump_flow_limit();
    row.limit = scaling::to_string(fout.limit);
    result.rows.push_back(row);

    sum.peak_tool_error_m = std::max(sum.peak_tool_error_m, error);
    sum_sq += error * error;
    if (sum.settled_at_s < 0.0 && error < kSettledErrorM) sum.settled_at_s = t;
    if (sum.settled_at_s >= 0.0) {
      sum.peak_tool_error_settled_m = std::max(sum.peak_tool_error_settled_m, error);
      sum_sq_settled += error * error;
      ++settled_cycles;
    }
    // With a shared pump the crane's flow counts against the same Q_max.
    const double pump_flow = row.flow_sum + (base.shared_with_crane ? row.arm_flow : 0.0);
    sum.peak_flow_ratio = std::max(sum.peak_flow_ratio, pump_flow / bm.pump_max_flow_m3_s);
    sum.peak_motor_flow_ratio =
        std::max(sum.peak_motor_flow_ratio, row.flow_sum / bm.pump_max_flow_m3_s);
    sum.peak_commanded_flow_ratio =
        std::max(sum.peak_commanded_flow_ratio, fout.wheels.flow_sum_m3_s / bm.pump_max_flow_m3_s);
    sum.peak_slew_rate_rad_s = std::max(sum.peak_slew_rate_rad_s, std::abs(state.qdot[0]));
    const Eigen::Vector2d xy(pose.x_m, pose.y_m);
    sum.platform_path_length_m += (xy - last_xy).norm();
    last_xy = xy;
    ++sum.cycles;

    if (fout.finished && finished_at < 0.0) {
      finished_at = t;
      sum.completion_time_s = t;
    }
    if (finished_at >= 0.0 && t - finished_at >= options.settle_s) break;
    machine.advance(period);
  }
  sum.rms_tool_error_m = std::sqrt(sum_sq / static_cast<double>(std::max<long>(1, sum.cycles)));
  sum.rms_tool_error_settled_m =
      settled_cycles > 0 ? std::sqrt(sum_sq_settled / static_cast<double>(settled_cycles)) : 0.0;
  if (!result.rows.empty()) {
    const FollowRow& last = result.rows.back();
    sum.final_platform_error_m = std::hypot(last.x - last.x_d, last.y - last.y_d);
  }
  return result;
}

void write_follow_csv(std::ostream& out, const FollowResult& result, const std::string& comment) {
  std::istringstream lines(comment);
  for (std::string line; std::getline(lines, line);) out << "# " << line << "\n";
  out << "t,s,sdot,x,y,phi,x_d,y_d,phi_d,e_x,e_y,e_phi,v_cmd,omega_cmd,v,omega,v_max,"
         "flow_fl,flow_fr,flow_rl,flow_rr,flow_sum,flow_max,steer_fl,steer_fr,steer_rl,steer_rr,"
         "tool_x,tool_y,tool_z,tool_x_d,tool_y_d,tool_z_d,tool_error,tool_error_filtered,delta,"
         "q1,q2,q3,q4,arm_flow,arm_flow_max,limit\n";
  out.precision(9);
  for (const FollowRow& r : result.rows) {
    out << r.t << ',' << r.s << ',' << r.sdot << ',' << r.x << ',' << r.y << ',' << r.phi << ','
        << r.x_d << ',' << r.y_d << ',' << r.phi_d << ',' << r.e_x << ',' << r.e_y << ',' << r.e_phi
        << ',' << r.v_cmd << ',' << r.omega_cmd << ',' << r.v << ',' << r.omega << ',' << r.v_max;
    for (const double f : r.flow) out << ',' << f;
    out << ',' << r.flow_sum << ',' << r.flow_max;
    for (const double a : r.steer) out << ',' << a;
    for (const double p : r.tool) out << ',' << p;
    for (const double p : r.tool_d) out << ',' << p;
    out << ',' << r.tool_error << ',' << r.tool_error_filtered << ',' << r.delta;
    for (const double q : r.q) out << ',' << q;
    out << ',' << r.arm_flow << ',' << r.arm_flow_max << ',' << r.limit << '\n';
  }
}

}  // namespace craneassist::studies
