#include "research/polytope_command.hpp"

#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <vector>

#include "crane_options.hpp"
#include "craneassist/dynamics/flow_polytope.hpp"
#include "craneassist/studies/polytope_report.hpp"
#include "embedded_replays.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"

extern char** environ;

namespace craneassist::cli {
namespace {

constexpr double kLpm = 1e-3 / 60.0;

using Plane = std::optional<Eigen::Matrix<double, 2, 3>>;

// "x,y,z" (or "a,b" in a planar arm's plane) as a crane-frame vector.
Eigen::Vector3d parse_direction(const std::string& text, const Plane& plane) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    char* end = nullptr;
    const double v = std::strtod(part.c_str(), &end);
    while (end != nullptr && *end == ' ') ++end;
    if (part.empty() || end == part.c_str() || *end != '\0' || !std::isfinite(v)) {
      throw CLI::ValidationError("--direction", "'" + text + "': expected numbers x,y,z");
    }
    values.push_back(v);
  }
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  if (values.size() == 3) {
    d = Eigen::Vector3d(values[0], values[1], values[2]);
  } else if (values.size() == 2 && plane) {
    d = plane->transpose() * Eigen::Vector2d(values[0], values[1]);
  } else {
    throw CLI::ValidationError("--direction", "'" + text + "': expected three numbers x,y,z" +
                                                  (plane ? " (or two in the arm's plane)" : ""));
  }
  const Eigen::Vector3d in_task = plane ? Eigen::Vector3d(plane->transpose() * (*plane * d)) : d;
  if (!(in_task.norm() > 0.0)) {
    throw CLI::ValidationError("--direction", "'" + text + "': not a direction the tip can take" +
                                                  (plane ? " (out of the arm's plane)" : ""));
  }
  return d;
}

// "slew 0.0 deg, lift 20.0 deg, tilt -70.0 deg, extension 1.000 m".
std::string pose_text(const dynamics::CraneModel& model, const dynamics::JointVector& q) {
  std::string text;
  for (int i = 0; i < model.dof(); ++i) {
    const auto& joint = model.joints[static_cast<std::size_t>(i)];
    char part[96];
    if (joint.type == dynamics::JointType::kRevolute) {
      std::snprintf(part, sizeof part, "%s%s %.1f deg", text.empty() ? "" : ", ",
                    joint.name.c_str(), q[i] * 180.0 / std::numbers::pi);
    } else {
      std::snprintf(part, sizeof part, "%s%s %.3f m", text.empty() ? "" : ", ", joint.name.c_str(),
                    q[i]);
    }
    text += part;
  }
  return text;
}

// A crane-frame vector in the report's task coordinates (a planar arm's: its plane's, third 0).
Eigen::Vector3d task_coordinates(const studies::PolytopeReport& r, const Eigen::Vector3d& v) {
  if (!r.plane) return v;
  const Eigen::Vector2d p = *r.plane * v;
  return {p.x(), p.y(), 0.0};
}

std::string vector_text(const Eigen::Vector3d& shown, int dim) {
  // Rounding dust below the printed digits (-1e-17) prints as 0, not -0.000.
  const Eigen::Vector3d v = shown.unaryExpr([](double x) { return std::abs(x) < 5e-4 ? 0.0 : x; });
  char text[96];
  if (dim == 3) {
    std::snprintf(text, sizeof text, "(%6.3f, %6.3f, %6.3f)", v.x(), v.y(), v.z());
  } else {
    std::snprintf(text, sizeof text, "(%6.3f, %6.3f)", v.x(), v.y());
  }
  return text;
}

void write_csv(const std::string& file, const studies::PolytopeReport& r, const std::string& title,
               const std::string& pose) {
  std::ofstream out(file);
  out.precision(12);
  const int dim = r.task_dim;
  out << "# title: " << title << "\n# pose: " << pose << "\n# dimension: " << r.dimension << "\n";
  if (dim == 3) out << "# volume_m3_s3: " << r.volume_m3_s3 << "\n";
  out << "# area_m2_s2: " << r.area_m2_s2 << "\n";
  out << "# resolution: " << r.resolution << "\n";
  if (!r.speeds.empty()) {
    const auto& s = r.speeds.front();
    const Eigen::Vector3d u = task_coordinates(r, s.direction);
    out << "# direction: " << u.x() << "," << u.y();
    if (dim == 3) out << "," << u.z();
    out << "\n# best_speed_m_s: " << s.best_m_s << "\n# resolved_speed_m_s: " << s.resolved_m_s
        << "\n";
  }
  for (int a = 0; a < dim; ++a)
    out << (a ? "," : "") << r.axis_names[static_cast<std::size_t>(a)] << "_m_s";
  for (Eigen::Index i = 0; i < (r.vertex_qdot.empty() ? 0 : r.vertex_qdot.front().size()); ++i) {
    out << ",qdot" << i + 1;
  }
  out << "\n";
  for (std::size_t k = 0; k < r.vertices.size(); ++k) {
    for (int a = 0; a < dim; ++a) out << (a ? "," : "") << r.vertices[k][a];
    for (Eigen::Index i = 0; i < r.vertex_qdot[k].size(); ++i) out << "," << r.vertex_qdot[k][i];
    out << "\n";
  }
  if (!out) throw std::runtime_error(file + ": cannot write");
}

// Runs the embedded tools/plot_polytope.py on the CSV with Debian's python3 (/usr/bin/python3,
// as the scripts in tools/ do: its matplotlib and scipy are the Debian packages; another
// python3 on the PATH need not have them), or the PATH's when there is none. Returns its exit
// code (127: no python3).
int run_plot(const std::string& csv, const std::string& png, const std::filesystem::path& dir) {
  const auto script = dir / "plot_polytope.py";
  {
    std::ofstream out(script);
    out << embedded::kPlotPolytopePy;
    if (!out) throw std::runtime_error(script.string() + ": cannot write");
  }
  std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  std::string script_arg = script.string(), csv_arg = csv, png_arg = png;
  char* argv[] = {python.data(), script_arg.data(), csv_arg.data(), png_arg.data(), nullptr};
  pid_t pid = 0;
  if (posix_spawnp(&pid, python.c_str(), nullptr, nullptr, argv, environ) != 0) return 127;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

}  // namespace

CLI::App* add_polytope_command(CLI::App& cli, PolytopeArgs& args) {
  auto* cmd = cli.add_subcommand(
      "polytope",
      "The flow manipulability polytope at a pose: the tip velocities the cylinders and the pump "
      "allow, its volume, and the admissible speed along a direction");
  add_config_option(*cmd, args.config_file);
  cmd->add_option("--pose", args.pose,
                  "The pose, e.g. \"lift=20 deg, tilt=-70 deg, extension=1 m\" (joints left out "
                  "keep the config's simulation.initial)");
  cmd->add_option("--direction", args.direction,
                  "A tip direction x,y,z in the crane frame (x forward, y up, z lateral; a planar "
                  "arm also takes a,b in its plane); default: each task axis both ways");
  cmd->add_option("--speed", args.speed_m_s,
                  "The stick's speed, m/s, that the controller's resolution is shaped for "
                  "(default: the most the machine gives along the direction)")
      ->check(FiniteRange(1e-3, 100.0));
  add_resolution_option(*cmd, args.resolution, "of the controller");
  cmd->add_option("--pump-max-flow", args.pump_max_flow,
                  "Override the pump's maximum flow, e.g. \"120 L/min\"");
  cmd->add_option("--modes", args.modes,
                  "An MHSB arm's mode per joint, N, DB or SB, e.g. \"N-DB-N\" (docs/mhsb.md; "
                  "default: all N)");
  cmd->add_option("--out", args.out, "Write the polytope's vertices to this CSV");
  cmd->add_option("--plot", args.plot,
                  "Draw the polytope into this PNG (tools/plot_polytope.py; needs python3 with "
                  "matplotlib and scipy)");
  return cmd;
}

int run_polytope_command(const PolytopeArgs& args) {
  config::CraneConfig cfg;
  dynamics::JointVector q;
  std::vector<Eigen::Vector3d> directions;
  std::optional<mhsb::ModePattern> modes;
  try {
    cfg = load_crane(args.config_file);
    apply_crane_options(cfg, {.resolution = args.resolution});
    if (!args.pump_max_flow.empty()) {
      const double flow =
          cli_quantity("--pump-max-flow", args.pump_max_flow, config::Dimension::kFlow);
      apply_override("--pump-max-flow", [&] { config::set_pump_max_flow(cfg.model, flow); });
    }
    q = cfg.simulation.q_initial;
    if (!args.pose.empty()) {
      try {
        q = config::parse_joint_pose(cfg.model, args.pose, q);
      } catch (const std::invalid_argument& e) {
        throw CLI::ValidationError("--pose", e.what());
      }
    }
    if (!args.modes.empty()) {
      if (!cfg.model.mhsb) {
        throw CLI::ValidationError("--modes",
                                   "the crane has no MHSB circuit (hydraulics.mhsb in its config)");
      }
      modes = mhsb::parse_mode_pattern(args.modes, cfg.model.dof());
      if (!modes) {
        throw CLI::ValidationError(
            "--modes", "'" + args.modes + "': expected one of N, DB, SB per joint (" +
                           std::to_string(cfg.model.dof()) + "), joined by '-', e.g. N-DB-N");
      }
      if (modes->modules() > cfg.model.mhsb->modules) {
        throw CLI::ValidationError(
            "--modes", "'" + args.modes + "' takes " + std::to_string(modes->modules()) +
                           " boost modules (DB one, SB two); the circuit has " +
                           std::to_string(cfg.model.mhsb->modules));
      }
    }
    const Plane plane = dynamics::planar_task_basis(cfg.model);
    if (!args.direction.empty()) {
      directions.push_back(parse_direction(args.direction, plane));
    } else {
      for (int a = 0; a < (plane ? 2 : 3); ++a) {
        const Eigen::Vector3d axis =
            plane ? Eigen::Vector3d(plane->row(a).transpose()) : Eigen::Vector3d::Unit(a);
        directions.push_back(axis);
        directions.push_back(-axis);
      }
    }
  } catch (const CLI::Error&) {
    throw;  // main() reports it as a usage error
  } catch (...) {
    return input_error_exit("config");
  }
  const studies::PolytopeReport r =
      studies::polytope_report(cfg, q, directions, args.speed_m_s, modes);

  const int dim = r.task_dim;
  const std::string pose = pose_text(cfg.model, q);
  std::printf("craneassist polytope: %s\n", cfg.model.name.c_str());
  std::string ends;
  for (const auto& j : r.joints_at_end) ends += (ends.empty() ? "at an end: " : ", ") + j;
  std::printf("  pose: %s (%s)\n", pose.c_str(),
              ends.empty() ? "no joint at an end" : ends.c_str());
  if (r.modes) {
    const auto& m = *cfg.model.mhsb;
    std::printf(
        "  MHSB modes %s: each servo-valve from its supply (N: P0 %.1f MPa; DB, SB: up to %.1f "
        "MPa) against its cylinder's load, DB one servo-pump's %.3f L/min, SB two; the main "
        "pump's %.2f L/min in all, less the %.0f %% reserve (%.2f L/min); joints at an end move "
        "only away from it\n",
        mhsb::to_string(*r.modes).c_str(), cfg.model.pump.supply_pressure_pa * 1e-6,
        mhsb::mode_supply_pressure_pa(cfg.model, mhsb::MhsbMode::kDecoupledBoost) * 1e-6,
        m.servo_pump_max_flow_m3_s / kLpm, cfg.model.pump.max_flow_m3_s / kLpm,
        100.0 * r.flow_reserve, r.max_flow_m3_s / kLpm);
    std::printf("  cylinder loads at the pose (gravity, + pushing the rod in):");
    for (int i = 0; i < cfg.model.dof(); ++i) {
      std::printf("%s %s %.0f N", i ? "," : "",
                  cfg.model.joints[static_cast<std::size_t>(i)].name.c_str(),
                  r.cylinder_force_n[i]);
    }
    std::printf("\n");
  } else {
    std::printf(
        "  limits: each cylinder's speed and the pump's %.0f L/min, less the %.0f %% reserve of "
        "the full scaling (%.1f L/min); joints at an end move only away from it\n",
        cfg.model.pump.max_flow_m3_s / kLpm, 100.0 * r.flow_reserve, r.max_flow_m3_s / kLpm);
  }
  if (dim == 3) {
    std::printf(
        "  joint-velocity set: %d vertices; tip polytope: %zu vertices, volume %.4g m^3/s^3",
        r.joint_vertices, r.vertices.size(), r.volume_m3_s3);
    if (r.dimension < 3) {
      std::printf(" (flat: a singular pose; area %.4g m^2/s^2 in its plane)", r.area_m2_s2);
    }
  } else {
    std::printf(
        "  planar arm (%s-%s plane): joint-velocity set %d vertices; tip polygon: %zu vertices, "
        "area %.4g m^2/s^2",
        r.axis_names[0].c_str(), r.axis_names[1].c_str(), r.joint_vertices, r.vertices.size(),
        r.area_m2_s2);
    if (r.dimension < 2) std::printf(" (a segment: a singular pose)");
  }
  std::printf("\n");
  std::printf(
      "  admissible tip speed along u, m/s: over every joint motion (LP) | along the controller's "
      "%s resolution (what bounds it)\n",
      r.resolution.c_str());
  for (const auto& s : r.speeds) {
    std::printf("    u = %s  %7.3f | %7.3f",
                vector_text(task_coordinates(r, s.direction), dim).c_str(), s.best_m_s,
                s.resolved_m_s);
    if (!s.resolved_limit.empty()) std::printf(" (%s)", s.resolved_limit.c_str());
    if (s.resolved_limit.empty()) std::printf(" (the resolution finds no joint motion for u here)");
    if (args.speed_m_s) std::printf(", shaped for %.2f m/s", s.intended_m_s);
    std::printf("\n");
  }
  if (!r.pattern_measures.empty()) {
    std::printf("  %s per mode pattern, %s (* the largest):\n", dim == 3 ? "volume" : "area",
                dim == 3 ? "m^3/s^3" : "m^2/s^2");
    double best = 0.0;
    for (const auto& [pattern, measure] : r.pattern_measures) best = std::max(best, measure);
    for (std::size_t k = 0; k < r.pattern_measures.size(); ++k) {
      const auto& [pattern, measure] = r.pattern_measures[k];
      char value[32];
      std::snprintf(value, sizeof value, "%.4g%s", measure,
                    measure == best && best > 0.0 ? "*" : "");
      std::printf("%s%-9s %-8s", k % 4 == 0 ? "    " : " ", mhsb::to_string(pattern).c_str(),
                  value);
      if (k % 4 == 3 || k + 1 == r.pattern_measures.size()) std::printf("\n");
    }
  }
  std::printf("  vertices, m/s (%s):\n",
              dim == 3 ? "crane frame: x forward, y up, z lateral"
                       : ("plane axes " + r.axis_names[0] + ", " + r.axis_names[1]).c_str());
  for (const auto& v : r.vertices) std::printf("    %s\n", vector_text(v, dim).c_str());

  const std::string title = cfg.model.name;
  try {
    if (!args.out.empty()) {
      write_csv(args.out, r, title, pose);
      spdlog::info("wrote {} ({} vertices)", args.out, r.vertices.size());
    }
    if (!args.plot.empty()) {
      const auto dir = std::filesystem::temp_directory_path() /
                       ("craneassist-polytope-" + std::to_string(::getpid()));
      std::filesystem::create_directories(dir);
      const std::string csv = args.out.empty() ? (dir / "polytope.csv").string() : args.out;
      if (args.out.empty()) write_csv(csv, r, title, pose);
      std::fflush(stdout);  // the report before the script's own lines
      const int code = run_plot(csv, args.plot, dir);
      std::filesystem::remove_all(dir);
      if (code != 0) {
        spdlog::error(
            "--plot: the plot script failed (exit {}); it needs python3 with matplotlib and scipy "
            "(Debian: python3-matplotlib python3-scipy)",
            code);
        return kExitRuntime;
      }
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace craneassist::cli
