#include "research/bound_command.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <optional>

#include "crane_options.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/files/text_file.hpp"
#include "craneassist/studies/path_bound.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"

namespace craneassist::cli {
namespace {

using studies::JointPath;
using studies::JointPathOptions;

// The header of a CSV file: its first line that is neither blank nor a comment.
std::string header_of(const std::string& text) {
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    start = end + 1;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    line.erase(std::remove_if(line.begin(), line.end(), [](char c) { return std::isspace(c); }),
               line.end());
    return line;
  }
  return "";
}

// Where the bound's time goes: "cylinder speed 62 %, accelerating (path bound) 19 %, ...",
// largest share first.
std::string time_shares(const paths::TimeOptimalResult& r,
                        const std::vector<paths::PathSample>& samples) {
  std::map<std::string, double> time;
  for (std::size_t k = 0; k < r.segments.size(); ++k) {
    const auto& seg = r.segments[k];
    const char* limit = seg.limit == scaling::ActiveLimit::kCylinderAcceleration ? "cylinder"
                        : seg.limit == scaling::ActiveLimit::kPower              ? "power"
                        : seg.limit == scaling::ActiveLimit::kPressure           ? "relief pressure"
                                                                                 : "path bound";
    std::string name;
    switch (seg.phase) {
      case paths::BoundPhase::kSpeedCap:
        name = seg.limit == scaling::ActiveLimit::kFlow            ? "pump flow"
               : seg.limit == scaling::ActiveLimit::kCylinderSpeed ? "cylinder speed"
                                                                   : samples[k + 1].cap_name;
        break;
      case paths::BoundPhase::kAccelerating:
        name = std::string("accelerating (") + limit + ")";
        break;
      case paths::BoundPhase::kDecelerating:
        name = std::string("decelerating (") + limit + ")";
        break;
    }
    time[name] += seg.time_s;
  }
  std::vector<std::pair<double, std::string>> sorted;
  for (const auto& [name, t] : time) sorted.emplace_back(t, name);
  std::sort(sorted.rbegin(), sorted.rend());
  std::string text;
  for (const auto& [t, name] : sorted) {
    char part[96];
    std::snprintf(part, sizeof part, "%s%s %.0f %%", text.empty() ? "" : ", ", name.c_str(),
                  100.0 * t / r.time_s);
    text += part;
  }
  return text;
}

}  // namespace

CLI::App* add_bound_command(CLI::App& cli, BoundArgs& args) {
  auto* bound = cli.add_subcommand(
      "bound",
      "Time-optimal traversal of a tip path or a replay under the scaler's limits, against the "
      "online scaler");
  bound
      ->add_option("file", args.file,
                   "Tip path CSV (t,x,y,z; docs/path-format.md) or replay CSV (t,v_x,v_y,v_z)")
      ->required()
      ->check(CLI::ExistingFile);
  add_config_option(*bound, args.config_file);
  add_payload_option(*bound, args.payload_kg);
  add_resolution_option(*bound, args.resolution, "of the controller that drives the path");
  add_sway_option(*bound, args.no_sway_damping);
  bound
      ->add_option("--start", args.start,
                   "A path file's start configuration: the shortest feasible extension or the "
                   "middle of the feasible range (paper 000)")
      ->check(CLI::IsMember(names_of(studies::kStartExtensions)))
      ->capture_default_str();
  bound->add_option("--ds", args.ds_m, "Path sample spacing, m")
      ->check(FiniteRange(1e-3, 0.1))
      ->capture_default_str();
  bound->add_option("--profile", args.profile_file,
                    "Write s, the bound's and the online scaler's path speed to this CSV");
  return bound;
}

int run_bound_command(const BoundArgs& args) {
  config::CraneConfig cfg;
  std::string header;
  std::optional<input::PrescribedPath> path;
  std::optional<input::Replay> replay;
  const char* format = "replay";  // the file's format, for its errors
  try {
    cfg = load_crane(args.config_file);
    apply_crane_options(cfg, {.payload_kg = args.payload_kg,
                              .resolution = args.resolution,
                              .no_sway_damping = args.no_sway_damping});
    std::string text;
    try {  // read once, with the CSV formats' size limit; the header says which format it is
      text = files::read_text_file(args.file, files::kMaxCsvBytes, "tip path and replay");
    } catch (const files::ReadError& e) {
      throw input::FileError(e.file(), 0, "", e.reason());
    }
    header = header_of(text);
    if (header == "t,x,y,z") {
      format = "path";
      path = input::PrescribedPath::parse(text, args.file);
    } else if (header.rfind("t,v_x,v_y,v_z", 0) == 0) {
      replay = input::Replay::parse(text, args.file);
    } else {
      spdlog::error("{}: header '{}': expected a tip path (t,x,y,z) or a replay (t,v_x,v_y,v_z)",
                    args.file, header);
      return kExitUsage;
    }
  } catch (const config::ConfigError& e) {
    spdlog::error("{}", e.what());
    return kExitUsage;
  } catch (const input::FileError& e) {
    spdlog::error("{}: {}", format, e.what());
    return kExitUsage;
  } catch (const std::invalid_argument& e) {
    spdlog::error("{}", e.what());
    return kExitUsage;
  }

  std::vector<JointPath> parts;
  std::vector<double> replay_times;
  // A path file is also driven with the jerk bound lifted (x kJerkLift): what is left of the
  // gap to the bound is then the scaler's, the rest the jerk bound's.
  constexpr double kJerkLift = 100.0;
  std::optional<JointPath> unjerked;
  std::optional<studies::BoundFigures> unjerked_figures;
  try {
    if (path) {
      JointPathOptions options;
      options.ds_m = args.ds_m;
      options.start = studies::parse_start_extension(args.start).value();
      parts.push_back(studies::joint_path_for(cfg, *path, options));
      auto lifted = cfg;
      lifted.scaling.jerk_max_m_s3 *= kJerkLift;
      unjerked = studies::joint_path_for(lifted, *path, options);
      unjerked_figures = studies::bound_figures(lifted, *unjerked);
    } else {
      parts = studies::joint_paths_from_replay(cfg, *replay, args.ds_m, replay_times);
    }
  } catch (const std::exception& e) {
    spdlog::error("{}: {}", args.file, e.what());
    return kExitRuntime;
  }
  std::printf("craneassist bound: %s on %s, payload %.0f kg\n", args.file.c_str(),
              cfg.model.name.c_str(), cfg.model.bodies.back().mass_kg);
  if (cfg.model.grapple.hangs() && cfg.scaling.sway_damping) {
    std::printf(
        "  the controller damps the grapple's swing: each start and stop takes half a swing "
        "period longer, which the bound does not (--no-sway-damping: without)\n");
  }
  std::printf(
      "  resolution %s; limits: pump flow and cylinder speeds (with the %.0f %% reserve), "
      "%s power with m(s), b(s), cylinder and path accelerations\n",
      config::resolution_description(cfg).c_str(), 100.0 * cfg.control.flow_reserve,
      cfg.scaling.power_bound == dynamics::PowerBound::kLoadSensing ? "load-sensing" : "baseline");
  if (path) {
    std::printf("  tip path %.2f m (%.1f s in the file), start extension %s (%.3f m)\n",
                path->length_m(), path->duration_s(), args.start.c_str(),
                parts.front().start_extension_m);
  } else {
    std::printf("  replay: %zu moving parts between rests, the operator's speed as a cap\n",
                parts.size());
  }
  double bound_total = 0.0, online_total = 0.0;
  std::ofstream profile;
  if (!args.profile_file.empty()) {
    profile.open(args.profile_file);
    if (!profile) {
      spdlog::error("{}: cannot write the profile", args.profile_file);
      return kExitRuntime;
    }
    profile << "part,s,sdot_bound,sdot_online\n";
  }
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const auto& part = parts[p];
    const auto figures = studies::bound_figures(cfg, part);
    if (!figures.bound.ok) {
      const int k = figures.bound.blocked_sample;
      if (k >= 0) {
        spdlog::error(
            "part {}: the path cannot be traversed: at s = {:.2f} m the limits leave no "
            "acceleration from rest (at most {:.3g} m/s^2: a load pressure above what the pump "
            "can give, or a joint at its end)",
            p + 1, part.samples[static_cast<std::size_t>(k)].s,
            figures.bound.blocked_acceleration_max);
      } else {
        spdlog::error("part {}: no admissible rest-to-rest traversal", p + 1);
      }
      return kExitRuntime;
    }
    const double online = path ? part.online_time_s : replay_times[p];
    bound_total += figures.bound.time_s;
    online_total += online;
    const double top = *std::max_element(figures.bound.sdot.begin(), figures.bound.sdot.end());
    if (parts.size() > 1) std::printf("  part %zu, %.2f m:\n", p + 1, figures.length_m);
    std::printf("  bound %.2f s (top speed %.2f m/s; time at: %s)\n", figures.bound.time_s, top,
                time_shares(figures.bound, part.samples).c_str());
    if (path) {
      std::printf(
          "  the controller: %.2f s, %.3f x the bound; its reference went %.2f m and "
          "stayed within %.2f m of the path%s; largest cylinder speed %.2f, cylinder "
          "acceleration %.2f and pump power %.2f of their limits\n",
          online, online / figures.bound.time_s, figures.length_m, part.online_deviation_m,
          part.online_arrived ? "" : " (it did NOT come to rest at the end)",
          part.online_speed_share, part.online_acceleration_share, part.online_power_share);
      if (unjerked_figures && unjerked_figures->bound.ok) {
        std::printf(
            "  with its jerk bound lifted (%.0f m/s^3): %.2f s, %.3f x the bound of its "
            "path (%.2f s; pump power up to %.2f of P_max): the rest of the gap is the "
            "time the %.1f m/s^3 jerk bound takes\n",
            cfg.scaling.jerk_max_m_s3 * kJerkLift, unjerked->online_time_s,
            unjerked->online_time_s / unjerked_figures->bound.time_s,
            unjerked_figures->bound.time_s, unjerked->online_power_share,
            cfg.scaling.jerk_max_m_s3);
      }
    } else {
      std::printf("    the replay took %.2f s, %.3f x the bound\n", online,
                  online / figures.bound.time_s);
    }
    if (profile) {
      for (std::size_t k = 0; k < part.samples.size(); ++k) {
        const double online_sdot = k < part.online_sdot.size() ? part.online_sdot[k] : 0.0;
        profile << p + 1 << ',' << part.samples[k].s << ',' << figures.bound.sdot[k] << ','
                << online_sdot << '\n';
      }
    }
  }
  if (!path) {
    std::printf("  total: bound %.2f s, the replay %.2f s: %.3f x the bound\n", bound_total,
                online_total, online_total / bound_total);
  }
  std::printf(
      "  (the bound has no jerk limit: a lower bound for any jerk bound; the online "
      "scaler's path jerk is at most %.1f m/s^3)\n",
      cfg.scaling.jerk_max_m_s3);
  return kExitOk;
}

}  // namespace craneassist::cli
