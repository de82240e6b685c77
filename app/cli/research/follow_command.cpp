#include "research/follow_command.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "crane_options.hpp"
#include "craneassist/config/base_config.hpp"
#include "craneassist/input/tool_path_file.hpp"
#include "craneassist/studies/mobile_follow.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"

namespace craneassist::cli {
namespace {

constexpr double kLpm = 1e-3 / 60.0;

// The file line of the via point nearest path parameter s (segment i runs over [i/n, (i+1)/n]).
std::size_t line_near(const input::ToolPathFile& file, double s) {
  const double n = static_cast<double>(file.via_m.size() - 1);
  const auto i = static_cast<std::size_t>(std::clamp(std::lround(s * n), 0L, static_cast<long>(n)));
  return file.lines[i];
}

}  // namespace

CLI::App* add_follow_command(CLI::App& cli, FollowArgs& args) {
  auto* cmd = cli.add_subcommand(
      "follow",
      "The crane on wheels follows a tool path: the platform under the drive pump's flow bound, "
      "the arm holding the tool, the platform slowed by the tool error (docs/mobile.md)");
  cmd->add_option("PATH", args.path_file,
                  "Tool-path file: via points x,y in the ground plane (docs/mobile.md)")
      ->required();
  add_config_option(*cmd, args.config_file);
  cmd->add_option("--base", args.base_file,
                  "Base config YAML (default: the embedded config/machines/mobile_base.yaml)");
  cmd->add_flag("--no-error-scaling", args.no_error_scaling,
                "Case 1 of the paper: the flow bound only, the platform not slowed by the tool "
                "error");
  cmd->add_option("--pump", args.pump,
                  "shared: one pump of the drive's pump_max_flow feeds the hub motors and the "
                  "crane, the crane getting what the motors leave; separate: the crane has its "
                  "own (default: the base config's drive.shared_with_crane)")
      ->check(CLI::IsMember({"shared", "separate"}));
  cmd->add_option("--log", args.log, "CSV log of every cycle (default follow.csv)");
  cmd->add_flag("--no-log", args.no_log, "Write no log");
  cmd->add_option("--height-amplitude", args.height_amplitude_m,
                  "Amplitude of the tool's height wave, m (default 1, the paper's)")
      ->check(FiniteRange(0.0, 10.0));
  cmd->add_option("--height-cycles", args.height_cycles,
                  "Height waves over the path (default 4: the paper's z = sin(8 pi s))")
      ->check(FiniteRange(0.0, 100.0));
  cmd->add_option("--max-duration", args.max_duration_s, "Give up after this long, s (default 600)")
      ->check(FiniteRange(1.0, 86400.0));
  return cmd;
}

int run_follow_command(const FollowArgs& args) {
  config::CraneConfig crane;
  config::BaseConfig base;
  input::ToolPathFile file;
  try {
    crane = load_crane(args.config_file);
    base = config::load_base_or_default(args.base_file);
  } catch (...) {
    return input_error_exit("config");
  }
  try {
    file = input::load_tool_path(args.path_file);
  } catch (...) {
    return input_error_exit("tool path");
  }
  if (!args.pump.empty()) base.shared_with_crane = args.pump == "shared";
  studies::FollowOptions options;
  options.error_scaling = !args.no_error_scaling;
  if (args.height_amplitude_m) options.height_amplitude_m = *args.height_amplitude_m;
  if (args.height_cycles) options.height_cycles = *args.height_cycles;
  if (args.max_duration_s) options.max_duration_s = *args.max_duration_s;

  const paths::CompositeBezierPath path(file.via_m);
  // What the platform cannot follow is the path's fault: named at the nearest via point.
  const double offset = base.following.tool_offset_m;
  const paths::OffsetPathCheck check = paths::check_offset_path(path, offset);
  const double kappa_max = dynamics::max_curvature_1_m(base.model);
  if (!(check.min_v_prime_m > 0.0)) {
    std::ostringstream why;
    why << "the platform's path, " << offset
        << " m beside the tool path (path_following.tool_offset), has a cusp here: the tool path "
           "turns tighter than that";
    spdlog::error("tool path: {}:{}: {}", file.source, line_near(file, check.min_v_prime_s),
                  why.str());
    return kExitUsage;
  }
  if (check.max_curvature_1_m > kappa_max) {
    std::ostringstream why;
    why.precision(3);
    why << "the platform's path turns on a radius of " << 1.0 / check.max_curvature_1_m
        << " m here, tighter than the steering allows (" << 1.0 / kappa_max
        << " m at the chassis centre)";
    spdlog::error("tool path: {}:{}: {}", file.source, line_near(file, check.max_curvature_s),
                  why.str());
    return kExitUsage;
  }

  studies::FollowResult result;
  try {
    result = studies::run_follow(crane, base, path, options);
  } catch (const std::invalid_argument& e) {
    spdlog::error("tool path: {}: {}", file.source, e.what());
    return kExitUsage;
  }
  const studies::FollowSummary& s = result.summary;
  std::printf("craneassist follow: %s, %s, %s\n", file.source.c_str(),
              options.error_scaling ? "flow bound and tool-error scaling (case 2)"
                                    : "flow bound only (case 1)",
              base.shared_with_crane ? "one pump for the drive and the crane"
                                     : "the crane on its own pump");
  std::printf("  tool path: %zu via points, %.2f m; platform %.2f m %s of it, driven %.2f m\n",
              file.via_m.size(), s.path_length_m, std::abs(offset), offset >= 0 ? "right" : "left",
              s.platform_path_length_m);
  std::printf(
      "  drive pump: %.1f L/min; peak sum of hub-motor flows %.1f L/min (%.3f of Q_max; "
      "commanded %.3f)\n",
      base.model.pump_max_flow_m3_s / kLpm,
      s.peak_motor_flow_ratio * base.model.pump_max_flow_m3_s / kLpm, s.peak_motor_flow_ratio,
      s.peak_commanded_flow_ratio);
  if (base.shared_with_crane) {
    std::printf("  shared with the crane: peak motors + crane %.1f L/min (%.3f of Q_max)\n",
                s.peak_flow_ratio * base.model.pump_max_flow_m3_s / kLpm, s.peak_flow_ratio);
  }
  if (s.completion_time_s >= 0) {
    std::printf("  completion time: %.2f s\n", s.completion_time_s);
  } else {
    std::printf("  completion time: not within %.0f s\n", options.max_duration_s);
  }
  std::printf("  tool error: peak %.3f m, RMS %.3f m\n", s.peak_tool_error_m, s.rms_tool_error_m);
  if (s.settled_at_s >= 0) {
    std::printf(
        "  after the start error was corrected (below 0.2 m at %.2f s): peak %.3f m, RMS "
        "%.3f m\n",
        s.settled_at_s, s.peak_tool_error_settled_m, s.rms_tool_error_settled_m);
  } else {
    std::printf("  the tool error never came below 0.2 m\n");
  }
  std::printf("  peak slew rate %.3f rad/s; platform %.3f m from its reference at the end\n",
              s.peak_slew_rate_rad_s, s.final_platform_error_m);
  if (!args.no_log) {
    std::ofstream out(args.log);
    std::ostringstream comment;
    comment << "craneassist follow " << file.source
            << (options.error_scaling ? "" : " --no-error-scaling")
            << (base.shared_with_crane ? " --pump shared" : "") << "\n"
            << "pump_max_flow_m3_s: " << base.model.pump_max_flow_m3_s << "\n"
            << "completion_time_s: " << s.completion_time_s;
    studies::write_follow_csv(out, result, comment.str());
    if (!out) {
      spdlog::error("{}: cannot write", args.log);
      return kExitRuntime;
    }
    spdlog::info("wrote {} ({} rows)", args.log, result.rows.size());
  }
  return kExitOk;
}

}  // namespace craneassist::cli
