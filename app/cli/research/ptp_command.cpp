#include "research/ptp_command.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <vector>

#include "crane_options.hpp"
#include "craneassist/input/joint_trajectory.hpp"
#include "craneassist/planner/ptp_planner.hpp"
#include "craneassist/studies/ptp_simulation.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"
#include "research/goal_planning.hpp"

namespace craneassist::cli {
namespace {

std::string point_text(const Eigen::Vector2d& p) {
  char text[64];
  std::snprintf(text, sizeof text, "(%.3f, %.3f) m", p.x(), p.y());
  return text;
}

// --simulate: the plan (and the goal changes' plans) on the MHSB simulator.
int simulate(planner::PtpPlanner& ptp, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
             const planner::PtpWeights& weights, const std::vector<studies::PtpGoalChange>& changes,
             const std::string& log_file, const planner::PtpPlan& plan) {
  std::ofstream log;
  if (!log_file.empty()) {
    log.open(log_file);
    if (!log) {
      spdlog::error("--sim-log: {}: cannot open for writing", log_file);
      return kExitRuntime;
    }
  }
  studies::PtpSimulation run;
  try {
    run = studies::simulate_ptp(ptp, from, to, weights, changes, 0.0,
                                log_file.empty() ? nullptr : &log);
  } catch (const std::exception& e) {
    spdlog::error("--simulate: {}", e.what());
    return kExitRuntime;
  }
  const auto& model = ptp.arm().model();
  const auto& m = run.measured;
  std::printf("  simulated (MHSB simulator, cascade controller, %.0f Hz): %.2f s\n",
              1.0 / mhsb::MhsbControllerSettings{}.period_s, run.duration_s);
  for (std::size_t i = 1; i < run.segments.size(); ++i) {
    const auto& s = run.segments[i];
    std::printf(
        "    goal changed at %.2f s to %s: replanned from %s in %.3f ms, %.2f s, %.0f J, %d "
        "mode switches\n",
        s.start_s, point_text(s.to).c_str(), point_text(s.from).c_str(),
        1000.0 * s.plan.planning_time_s, s.plan.time_s, s.plan.energy_j, s.plan.switches);
  }
  std::printf(
      "    energy measured %.0f J (main pump %.0f, servo-pumps %.0f) against %.0f J planned "
      "(%+.1f %%)\n",
      m.energy_j, m.main_energy_j, m.servo_pump_energy_j, run.planned_energy_j,
      100.0 * (m.energy_j - run.planned_energy_j) / run.planned_energy_j);
  std::string errors, supply;
  for (int k = 0; k < ptp.arm().moving(); ++k) {
    const int j = ptp.arm().joint(k);
    char part[96];
    std::snprintf(part, sizeof part, "%s%s %.2f", k ? ", " : "",
                  model.joints[static_cast<std::size_t>(j)].name.c_str(),
                  m.max_abs_error[j] * 180.0 / M_PI);
    errors += part;
    std::snprintf(part, sizeof part, "%s%s %.1f", k ? ", " : "",
                  model.joints[static_cast<std::size_t>(j)].name.c_str(),
                  m.max_p_supply_pa[j] * 1e-6);
    supply += part;
  }
  std::printf("    largest joint error, deg: %s (at the end %.3f deg)\n", errors.c_str(),
              run.final_error_rad * 180.0 / M_PI);
  std::printf("    highest supply pressure, MPa: %s\n", supply.c_str());
  if (m.invalid_references > 0 || m.dynamics_failures > 0) {
    spdlog::warn("--simulate: {} invalid references, {} failed dynamics steps",
                 m.invalid_references, m.dynamics_failures);
  }
  (void)plan;
  if (!log_file.empty()) std::printf("    log: %s\n", log_file.c_str());
  return kExitOk;
}

// --path-out: the S2 path's nodes, and when the time trajectory passes each.
int write_path(const planner::PlanarArm& arm, const planner::PostureTable& table,
               const planner::PtpPlan& plan, const std::string& file) {
  std::ostringstream out;
  out << "# craneassist ptp: the S2 path (docs/mhsb.md); t_s, energy_j: S2's arrival and energy "
         "spent; t_trajectory_s: when the S3/S4 trajectory passes the node; q: the moving "
         "joints, rad; area_m2_s2: the posture's flow manipulability polytope area\n";
  out << "step,x_m,z_m,pattern,t_s,energy_j,t_trajectory_s,area_m2_s2";
  for (int k = 0; k < arm.moving(); ++k) {
    out << ",q_" << arm.model().joints[static_cast<std::size_t>(arm.joint(k))].name << "_rad";
  }
  out << '\n';
  const auto& steps = plan.path.steps;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const auto& s = steps[i];
    const Eigen::Vector2d xz = table.grid().node_xz[static_cast<std::size_t>(s.node)];
    char line[200];
    std::snprintf(line, sizeof line, "%zu,%.4f,%.4f,%s,%.4f,%.3f,%.4f,%.6g", i, xz.x(), xz.y(),
                  mhsb::to_string(table.patterns()[static_cast<std::size_t>(s.pattern)]).c_str(),
                  s.t_s, s.energy_j, i < plan.node_times_s.size() ? plan.node_times_s[i] : s.t_s,
                  table.area(s.node, s.pattern));
    out << line;
    for (int k = 0; k < arm.moving(); ++k) {
      std::snprintf(line, sizeof line, ",%.6f", s.q[k]);
      out << line;
    }
    out << '\n';
  }
  char what[64];
  std::snprintf(what, sizeof what, "%zu S2 nodes", steps.size());
  return write_output(out.str(), file, what);
}

// --workspace-out: per node the all-N posture, its polytope area, and per moving joint whether it
// needs a boost there (mhsb::needs_boost) to hold its load from P0, and to move against it at
// V_L.
int write_workspace(const planner::PtpPlanner& ptp, const std::string& file) {
  const planner::PlanarArm& arm = ptp.arm();
  const planner::PostureTable& table = ptp.table();
  int all_n = -1;
  for (int p = 0; p < table.pattern_count() && all_n < 0; ++p) {
    bool n = true;
    for (int k = 0; k < arm.moving(); ++k) {
      n = n && table.patterns()[static_cast<std::size_t>(p)].mode[static_cast<std::size_t>(k)] ==
                   mhsb::MhsbMode::kNormal;
    }
    if (n) all_n = p;
  }
  const auto& model = arm.model();
  std::ostringstream out;
  out << "# craneassist ptp: the posture table's grid (" << table.grid().nodes()
      << " nodes) with the all-N posture (rad), its polytope area (m^2/s^2), the cylinder forces "
         "that hold the load (N) and whether each joint needs a boost from P0 (1) or not (0) to "
         "hold it (hold_) and to move against it at V_L (lift_)\n";
  out << "x_m,z_m,area_m2_s2";
  for (int k = 0; k < arm.moving(); ++k) {
    const auto& name = model.joints[static_cast<std::size_t>(arm.joint(k))].name;
    out << ",q_" << name << "_rad,force_" << name << "_n,hold_" << name << ",lift_" << name;
  }
  out << '\n';
  dynamics::KinematicsData data;
  planner::PlanarArm::Statics statics;
  for (int n = 0; n < table.grid().nodes(); ++n) {
    const Eigen::Vector2d xz = table.grid().node_xz[static_cast<std::size_t>(n)];
    const planner::ArmVector q = table.posture(n, all_n);
    arm.statics(q, data, statics);
    char line[160];
    std::snprintf(line, sizeof line, "%.4f,%.4f,%.6g", xz.x(), xz.y(), table.area(n, all_n));
    out << line;
    for (int k = 0; k < arm.moving(); ++k) {
      const double f = statics.force_n[k], direction = f < 0.0 ? -1.0 : 1.0;
      const bool hold = mhsb::needs_boost(model, arm.joint(k), f, 1e-9 * direction);
      const bool lift =
          mhsb::needs_boost(model, arm.joint(k), f, ptp.velocity_limit_m_s(k) * direction);
      std::snprintf(line, sizeof line, ",%.6f,%.1f,%d,%d", q[k], f, hold ? 1 : 0, lift ? 1 : 0);
      out << line;
    }
    out << '\n';
  }
  char what[64];
  std::snprintf(what, sizeof what, "%d nodes", table.grid().nodes());
  return write_output(out.str(), file, what);
}

}  // namespace

// "a,b,..." as exactly `count` finite numbers, or a CLI::ValidationError naming the option.
std::vector<double> parse_numbers(const std::string& option, const std::string& text,
                                  std::size_t count, const char* what) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string part;
  bool ok = true;
  while (std::getline(in, part, ',')) {
    char* end = nullptr;
    const double v = std::strtod(part.c_str(), &end);
    while (end != nullptr && *end == ' ') ++end;
    ok = ok && !part.empty() && end != part.c_str() && *end == '\0' && std::isfinite(v);
    values.push_back(v);
  }
  if (!ok || values.size() != count || (!text.empty() && text.back() == ',')) {
    throw CLI::ValidationError(option, "'" + text + "': expected " + what);
  }
  return values;
}

planner::PtpWeights parse_weights(const std::string& option, const std::string& text) {
  const auto w = parse_numbers(option, text, 3, "three numbers w1,w2,w3");
  for (const double x : w) {
    if (x < 0.0) throw CLI::ValidationError(option, "'" + text + "': negative");
  }
  planner::PtpWeights weights;
  weights.energy = w[0];
  weights.time = w[1];
  weights.switches = w[2];
  return weights;
}

double parse_grid_spacing(const std::string& option, const std::string& text) {
  const double spacing_m = cli_quantity(option, text, config::Dimension::kLength);
  if (!(spacing_m >= 0.005 && spacing_m <= 5.0)) {
    throw CLI::ValidationError(option, "must be between 5 mm and 5 m");
  }
  return spacing_m;
}

void check_grid_size(const planner::PlanarArm& arm, const std::string& crane, double spacing_m,
                     const std::string& option) {
  const double cells = planner::grid_cells(arm, spacing_m);
  if (cells > planner::kMaxGridCells) {
    const double finest = 2.0 * planner::arm_reach_m(arm) / std::sqrt(planner::kMaxGridCells);
    char why[240];
    std::snprintf(why, sizeof why,
                  "%.0f mm gives up to %.3g grid cells for %s (reach %.2f m): its table would "
                  "take hours; at most %.3g cells, %.0f mm or coarser",
                  1000.0 * spacing_m, cells, crane.c_str(), planner::arm_reach_m(arm),
                  planner::kMaxGridCells, std::ceil(1000.0 * finest));
    throw CLI::ValidationError(option, why);
  }
}

void check_in_workspace(const planner::WorkspaceGrid& grid, const std::string& crane,
                        const std::vector<std::pair<std::string, Eigen::Vector2d>>& points) {
  const double reach = 0.5 * std::sqrt(2.0) * grid.spacing_m + 1e-9;
  for (const auto& [option, p] : points) {
    if (grid.nearest_node(p, reach) < 0) {
      char why[160];
      std::snprintf(why, sizeof why,
                    "%s is outside the workspace of %s (no reachable grid node within %.1f cm)",
                    point_text(p).c_str(), crane.c_str(), 100.0 * reach);
      throw CLI::ValidationError(option, why);
    }
  }
}

LoadedTable posture_table_for(const config::CraneConfig& cfg, const planner::PlanarArm& arm,
                              const planner::PostureTableSettings& settings,
                              const std::string& table_option,
                              const std::vector<std::pair<std::string, Eigen::Vector2d>>& points) {
  LoadedTable out;
  out.file = table_option.empty() ? planner::default_table_file(arm, settings)
                                  : std::optional<std::filesystem::path>(table_option);
  std::optional<planner::PostureTable> table;
  if (out.file) table = planner::PostureTable::load(*out.file, arm, settings);
  out.loaded = table.has_value();
  if (out.loaded) {
    check_in_workspace(table->grid(), cfg.model.name, points);
  } else {
    check_in_workspace(planner::sample_workspace(arm, settings).grid, cfg.model.name, points);
    std::fprintf(stderr, "craneassist: building the posture table (%d threads)...\n",
                 settings.threads);
    table = planner::PostureTable::build(arm, settings);
    if (out.file) {
      try {
        table->save(*out.file);
      } catch (const std::exception& e) {
        spdlog::warn("{} (the table is not cached)", e.what());
      }
    }
  }
  out.table = std::move(*table);
  return out;
}

CLI::App* add_ptp_command(CLI::App& cli, PtpArgs& args) {
  auto* cmd = cli.add_subcommand(
      "ptp",
      "Plan an energy-optimal point-to-point move of the tip in the arm's vertical plane with "
      "posture and MHSB modes (paper 001: posture table, A*, time trajectory, mode retiming)");
  add_config_option(*cmd, args.config_file);
  cmd->add_option("--from", args.from, "Start X,Z in m (X horizontal outwards, Z up)")->required();
  cmd->add_option("--to", args.to, "Goal X,Z in m")->required();
  cmd->add_option("--weights", args.weights,
                  "w1,w2,w3: weights of energy (per J), time (per s) and mode switches (per "
                  "switched joint); default 0.5,0,2 (paper 001 case 1-1)");
  cmd->add_option("--velocity-limit", args.velocity_limit,
                  "The cylinders' speed limit V_L, e.g. \"12 mm/s\" (default: "
                  "hydraulics.mhsb.velocity_limit, or each cylinder's max_speed)");
  cmd->add_option("--grid", args.grid,
                  "Grid spacing, e.g. \"5 cm\" (default 5 cm, or reach / 40 for a larger arm)");
  cmd->add_option("--energy-model", args.energy_model,
                  "MHSB energy: series (default: main pump at P0, servo-pump adds the boost at its "
                  "efficiency) or paper (eq. 9 as printed)")
      ->check(CLI::IsMember({"series", "paper"}));
  cmd->add_option("--table", args.table,
                  "The posture table file (built and written when missing or out of date; "
                  "default: $XDG_CACHE_HOME or ~/.cache, craneassist/ptp-table-<hash>.bin)");
  cmd->add_option("--heuristic-scale", args.heuristic_scale,
                  "k of the A* heuristic k * distance (cost per m; default: the admissible bound, "
                  "which keeps A* optimal)")
      ->check(FiniteRange(0.0, 1e12));
  cmd->add_option("--threads", args.threads, "Threads for building the posture table (default 2)")
      ->check(CLI::Range(1, 64));
  cmd->add_option("--continuity-tolerance", args.continuity_tolerance,
                  "Posture table: of the postures within this fraction of a node's largest "
                  "polytope area, keep the one nearest the neighbouring nodes' (e.g. 0.3; "
                  "default 0: the largest, paper 001's S1)")
      ->check(FiniteRange(0.0, 0.99));
  cmd->add_option("--posture", args.posture,
                  "Where the postures come from: optimal (default; the optimal posture table, "
                  "S1) or fixed-last:ANGLE (the conventional method of paper 001's Case 4: the "
                  "last joint held at ANGLE, degrees or with a unit, changed 1 deg at a time "
                  "where the other joints cannot reach a node)");
  cmd->add_option("-o,--out", args.out, "Write the joint trajectory with mode columns to this CSV");
  cmd->add_option(
      "--path-out", args.path_out,
      "Write the S2 path's nodes (X, Z, mode pattern, time, energy, polytope area, posture) to "
      "this CSV");
  cmd->add_option("--workspace-out", args.workspace_out,
                  "Write the grid's nodes with the all-N posture of the posture table, its "
                  "polytope area and which joints need a boost to hold the load there, to this "
                  "CSV (the mode regions of paper 001's Figure 5)");
  cmd->add_flag("--simulate", args.simulate,
                "Run the plan on the MHSB simulator under the paper's cascade controller and "
                "compare the measured energy with the planned (docs/mhsb.md)");
  cmd->add_option("--sim-log", args.simulate_log,
                  "With --simulate: the simulator's per-period CSV (docs/mhsb-simulator.md)");
  cmd->add_option("--goal-at", args.goal_at,
                  "With --simulate: T:X,Z changes the goal at T s, replanned from where the arm "
                  "is (repeatable; paper 001 section 4.2)");
  return cmd;
}

int run_ptp_command(const PtpArgs& args) {
  config::CraneConfig cfg;
  std::optional<planner::PlanarArm> arm;
  planner::PtpSettings settings;
  planner::PostureTableSettings table_settings;
  planner::PtpWeights weights;
  Eigen::Vector2d from, to;
  std::vector<studies::PtpGoalChange> goal_changes;
  std::optional<double> fixed_last;  // --posture fixed-last:ANGLE, rad
  try {
    cfg = load_crane(args.config_file);
    try {
      arm.emplace(cfg.model, cfg.simulation.q_initial);
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--config", cfg.model.name + ": " + e.what());
    }
    const auto f = parse_numbers("--from", args.from, 2, "two numbers X,Z (m)");
    const auto t = parse_numbers("--to", args.to, 2, "two numbers X,Z (m)");
    from = {f[0], f[1]};
    to = {t[0], t[1]};
    weights = parse_weights("--weights", args.weights);
    weights.heuristic_per_m = args.heuristic_scale;
    if (!args.velocity_limit.empty()) {
      settings.velocity_limit_m_s =
          cli_quantity("--velocity-limit", args.velocity_limit, config::Dimension::kVelocity);
      if (!(settings.velocity_limit_m_s > 0.0 && settings.velocity_limit_m_s <= 10.0)) {
        throw CLI::ValidationError("--velocity-limit", "must be positive and at most 10 m/s");
      }
    }
    if (!args.grid.empty()) {
      table_settings.spacing_m = parse_grid_spacing("--grid", args.grid);
      check_grid_size(*arm, cfg.model.name, table_settings.spacing_m, "--grid");
    }
    if (!args.energy_model.empty()) {
      if (!cfg.model.mhsb) {
        throw CLI::ValidationError("--energy-model", cfg.model.name +
                                                         " has no MHSB circuit "
                                                         "(hydraulics.mhsb); its pump's energy "
                                                         "is used");
      }
      settings.energy_model = *mhsb::parse_mhsb_energy_model(args.energy_model);
    }
    table_settings.threads = args.threads;
    table_settings.continuity_tolerance = args.continuity_tolerance;
    if (args.posture != "optimal") {
      const std::string prefix = "fixed-last:";
      if (args.posture.rfind(prefix, 0) != 0 || args.posture.size() == prefix.size()) {
        throw CLI::ValidationError("--posture",
                                   "'" + args.posture + "': expected optimal or fixed-last:ANGLE");
      }
      const std::string angle = args.posture.substr(prefix.size());
      char* end = nullptr;
      const double deg = std::strtod(angle.c_str(), &end);
      fixed_last = end != angle.c_str() && *end == '\0' && std::isfinite(deg)
                       ? deg * M_PI / 180.0
                       : cli_quantity("--posture", angle, config::Dimension::kAngle);
    }
    if (!args.goal_at.empty() && !args.simulate) {
      throw CLI::ValidationError("--goal-at", "goal changes need --simulate");
    }
    if (!args.simulate_log.empty() && !args.simulate) {
      throw CLI::ValidationError("--sim-log", "needs --simulate");
    }
    if (args.simulate && !cfg.model.mhsb) {
      throw CLI::ValidationError(
          "--simulate", cfg.model.name +
                            " has no MHSB circuit; run its plan on the crane simulator with "
                            "craneassist replay --trajectory FILE (or sim --input goal)");
    }
    for (const GoalAt& g : parse_goals("", args.goal_at)) goal_changes.push_back({g.t_s, g.xz});
  } catch (const CLI::Error&) {
    throw;
  } catch (...) {
    return input_error_exit("config");
  }

  // The table: with --posture fixed-last built by that rule (quick, not cached); else from its
  // file when it matches, or built and written.
  std::vector<std::pair<std::string, Eigen::Vector2d>> points{{"--from", from}, {"--to", to}};
  for (const auto& g : goal_changes) points.emplace_back("--goal-at", g.xz);
  std::optional<std::filesystem::path> file;
  bool loaded = false;
  std::optional<planner::PostureTable> table;
  if (fixed_last) {
    try {
      table = planner::PostureTable::fixed_last_joint(*arm, table_settings, *fixed_last);
    } catch (const std::invalid_argument& e) {
      spdlog::error("--posture: {}: {}", cfg.model.name, e.what());
      return kExitUsage;
    }
    check_in_workspace(table->grid(), cfg.model.name, points);
  } else {
    LoadedTable loaded_table = posture_table_for(cfg, *arm, table_settings, args.table, points);
    file = loaded_table.file;
    loaded = loaded_table.loaded;
    table = std::move(loaded_table.table);
  }
  planner::PtpPlanner ptp(*arm, *table, settings);
  planner::PtpPlan plan;
  try {
    plan = ptp.plan(from, to, weights);
  } catch (const std::invalid_argument& e) {
    spdlog::error("{}", e.what());
    return kExitUsage;
  }

  const auto& grid = table->grid();
  std::printf("craneassist ptp: %s\n", cfg.model.name.c_str());
  char continuity[64] = "";
  if (table_settings.continuity_tolerance > 0.0 && !fixed_last) {
    std::snprintf(continuity, sizeof continuity, ", continuity tolerance %.3g %%",
                  100.0 * table_settings.continuity_tolerance);
  }
  std::printf("  posture table: %d nodes x %d patterns, %.0f mm grid%s, %s\n", grid.nodes(),
              table->pattern_count(), 1000.0 * grid.spacing_m, continuity,
              loaded ? ("loaded from " + file->string()).c_str() : "built");
  if (fixed_last) {
    std::printf(
        "    postures: %s held at %.1f deg, the others by inverse kinematics (paper 001 Case 4's "
        "conventional method), %ld nodes with %s moved; %.2f s\n",
        cfg.model.joints[static_cast<std::size_t>(arm->joint(arm->moving() - 1))].name.c_str(),
        *fixed_last * 180.0 / M_PI, table->moved_last_joint,
        cfg.model.joints[static_cast<std::size_t>(arm->joint(arm->moving() - 1))].name.c_str(),
        table->build_time_s);
  } else if (!loaded) {
    std::printf(
        "    in %.1f s (%d threads, %ld SLSQP runs, %ld entries without a converged run, %ld "
        "without polytope area, %ld kept off the best for continuity)%s\n",
        table->build_time_s, table_settings.threads, table->optimisations, table->unconverged,
        table->degenerate, table->continued,
        file ? (", written to " + file->string()).c_str() : "");
  }
  {
    // Posture jumps between neighbouring nodes (docs/mhsb.md#where-and-why-our-figures-differ);
    // pattern 0 is all N.
    long all = 0;
    for (int p = 0; p < table->pattern_count(); ++p) all += table->jumps(*arm, p);
    std::printf(
        "    posture jumps (a joint moving over a quarter of its range between neighbouring "
        "nodes): %d of %d pairs all N, %ld of %ld over all patterns\n",
        table->jumps(*arm, 0), table->neighbour_pairs(), all,
        static_cast<long>(table->neighbour_pairs()) * table->pattern_count());
  }
  std::string limits;
  for (int k = 0; k < arm->moving(); ++k) {
    char part[64];
    std::snprintf(part, sizeof part, "%s%.1f", k ? "/" : "", 1000.0 * ptp.velocity_limit_m_s(k));
    limits += part;
  }
  std::printf("  graph: %ld transitions; V_L %s mm/s; energy: %s\n", ptp.transitions(),
              limits.c_str(), planner::to_string(ptp.energy()));
  std::printf("  from %s to %s (nodes %s, %s), weights %g, %g, %g; heuristic %.4g per m\n",
              point_text(from).c_str(), point_text(to).c_str(),
              point_text(grid.node_xz[static_cast<std::size_t>(ptp.node_near(from))]).c_str(),
              point_text(grid.node_xz[static_cast<std::size_t>(ptp.node_near(to))]).c_str(),
              weights.energy, weights.time, weights.switches, ptp.heuristic_per_m(weights));
  if (!plan.path.found) {
    std::printf("  no path: the goal cannot be reached within the mode rules\n");
    return kExitRuntime;
  }
  const auto& path = plan.path;
  std::printf(
      "  S2 path: %zu nodes, %.3f m, %.2f s, %.0f J, %d mode switches (cost %.4g, %d "
      "states expanded)\n",
      path.steps.size(), path.length_m, path.time_s, path.energy_j, path.switches, path.cost,
      path.expanded);
  std::printf(
      "  S3/S4 trajectory: %.2f s, %.0f J, tip path %.3f m, %d mode switches, peak "
      "cylinder speed %.2f V_L\n",
      plan.time_s, plan.energy_j, plan.length_m, plan.switches, plan.peak_speed_ratio);
  std::printf("  planning time (S2-S4): %.3f ms\n", 1000.0 * plan.planning_time_s);
  std::string modes_line;
  for (std::size_t i = 0; i < path.steps.size(); ++i) {
    const auto& p = table->patterns()[static_cast<std::size_t>(path.steps[i].pattern)];
    if (i == 0 || !(p == table->patterns()[static_cast<std::size_t>(path.steps[i - 1].pattern)])) {
      char part[96];
      std::snprintf(part, sizeof part, "%s%s from %.2f s", modes_line.empty() ? "" : ", ",
                    mhsb::to_string(p).c_str(), i == 0 ? 0.0 : path.steps[i - 1].t_s);
      modes_line += part;
    }
  }
  if (cfg.model.mhsb) std::printf("  S2 modes: %s\n", modes_line.c_str());

  if (!args.path_out.empty()) {
    if (const int rc = write_path(*arm, *table, plan, args.path_out); rc != kExitOk) return rc;
  }
  if (!args.workspace_out.empty()) {
    if (const int rc = write_workspace(ptp, args.workspace_out); rc != kExitOk) return rc;
  }
  if (args.simulate) {
    if (const int rc = simulate(ptp, from, to, weights, goal_changes, args.simulate_log, plan);
        rc != kExitOk) {
      return rc;
    }
  }
  if (!args.out.empty()) {
    const int n = cfg.model.dof();
    input::JointTrajectory traj(n);
    traj.comments.push_back("craneassist ptp: " + cfg.model.name + ", from " + point_text(from) +
                            " to " + point_text(to) + ", weights " + args.weights);
    char summary[200];
    std::snprintf(summary, sizeof summary,
                  "energy %.1f J, time %.3f s, tip path %.3f m, mode switches %d (S2: %.1f J, "
                  "%.3f s)",
                  plan.energy_j, plan.time_s, plan.length_m, plan.switches, path.energy_j,
                  path.time_s);
    traj.comments.emplace_back(summary);
    Eigen::VectorXd qdot(n), qddot(n);
    std::vector<int> modes(static_cast<std::size_t>(n), 0);
    for (const auto& s : plan.samples) {
      const dynamics::JointVector q = arm->full(s.q);
      qdot.setZero();
      qddot.setZero();
      std::fill(modes.begin(), modes.end(), 0);
      for (int k = 0; k < arm->moving(); ++k) {
        qdot[arm->joint(k)] = s.qdot[k];
        qddot[arm->joint(k)] = s.qddot[k];
        modes[static_cast<std::size_t>(arm->joint(k))] =
            static_cast<int>(s.mode[static_cast<std::size_t>(k)]);
      }
      if (cfg.model.mhsb) {
        traj.append(s.t_s, Eigen::VectorXd(q), qdot, qddot, modes);
      } else {
        traj.append(s.t_s, Eigen::VectorXd(q), qdot, qddot);
      }
    }
    std::ostringstream text;
    input::write_joint_trajectory(text, traj);
    char what[64];
    std::snprintf(what, sizeof what, "%zu samples", traj.size());
    return write_output(text.str(), args.out, what);
  }
  return kExitOk;
}

}  // namespace craneassist::cli
