#include "research/plan_command.hpp"

#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>

#include "crane_options.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/studies/planning.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"

namespace craneassist::cli {

bool parse_dp_grid(const std::string& text, planner::DpGrid& grid) {
  int a = 0, b = 0, c = 0;
  char x1 = 0, x2 = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c%d%c", &a, &x1, &b, &x2, &c, &extra) != 5) return false;
  if (x1 != 'x' || x2 != 'x' || a < 2 || b < 2 || c < 2 || a > 5000 || b > 5000 || c > 5000) {
    return false;
  }
  grid = {a, b, c};
  return true;
}

namespace {

double peak_memory_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: kilobytes
}

// Progress on stderr: one line rewritten in place on a terminal, a line per 10 % otherwise.
class Progress {
 public:
  explicit Progress(bool quiet) : quiet_(quiet), tty_(isatty(STDERR_FILENO) != 0) {}
  void operator()(int done, int all) {
    if (quiet_ || all <= 0) return;
    const int percent = 100 * done / all;
    if (tty_) {
      std::fprintf(stderr, "\r  backward phase: %3d %% (%d/%d stages)", percent, done, all);
      if (done == all) std::fprintf(stderr, "\n");
    } else if (percent / 10 != last_ / 10 || done == all) {
      std::fprintf(stderr, "  backward phase: %d %% (%d/%d stages)\n", percent, done, all);
    }
    last_ = percent;
  }

 private:
  bool quiet_, tty_;
  int last_ = -1;
};

}  // namespace

CLI::App* add_plan_command(CLI::App& cli, PlanArgs& args) {
  auto* plan = cli.add_subcommand(
      "plan",
      "Plan the redundancy along a prescribed tip path (offline dynamic programming, or an "
      "online resolution as a baseline) and write the joint trajectory");
  plan->add_option("path", args.path_file, "Tip path CSV (t,x,y,z); see docs/path-format.md")
      ->required()
      ->check(CLI::ExistingFile);
  plan->add_option("--cost", args.cost,
                   "What to minimise: ls (load-sensing pump energy), cp (constant-pressure pump "
                   "energy), actuator-energy (positive cylinder work), extension (extension use)")
      ->check(CLI::IsMember(names_of(planner::kPlanCosts)))
      ->capture_default_str();
  plan->add_option("--method", args.method,
                   "dp (the global planner) or an online resolution driven along the path: "
                   "pinv-joint, pinv-actuator, min-flow, min-ls-power")
      ->check(CLI::IsMember(studies::plan_methods()))
      ->capture_default_str();
  plan->add_option("--out", args.out_file,
                   "Joint trajectory CSV to write (docs/trajectory-format.md)")
      ->capture_default_str();
  plan->add_option("--start", args.start,
                   "Start configuration: shortest feasible extension, or the middle of the "
                   "feasible range")
      ->check(CLI::IsMember(names_of(studies::kStartExtensions)))
      ->capture_default_str();
  plan->add_option("--grid", args.grid,
                   "DP grid: positions x velocities x accelerations of the extension cylinder")
      ->capture_default_str();
  plan->add_option("--refine", args.refine, "DP refinement passes in a tube around the solution")
      ->check(CLI::Range(0, 10))
      ->capture_default_str();
  plan->add_option("--threads", args.threads, "Worker threads (0: one per core)")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  plan->add_option("--dt", args.dt_s, "Stage length, s")
      ->check(FiniteRange(0.005, 1.0))
      ->capture_default_str();
  add_config_option(*plan, args.config_file);
  add_payload_option(*plan, args.payload_kg);
  plan->add_flag("--quiet", args.quiet, "No progress output");
  return plan;
}

int run_plan_command(const PlanArgs& args) {
  config::CraneConfig cfg;
  std::optional<input::PrescribedPath> path;
  planner::DpOptions dp;
  planner::StageModelOptions stage_options;
  studies::StartExtension start = studies::StartExtension::kShortest;
  try {
    cfg = load_crane(args.config_file);
    apply_crane_options(cfg, {.payload_kg = args.payload_kg});
    path = input::PrescribedPath::load_file(args.path_file);
    if (!parse_dp_grid(args.grid, dp.grid)) {
      throw CLI::ValidationError(
          "--grid", "expected three counts 2..5000 like 356x101x151, got '" + args.grid + "'");
    }
    stage_options.cost = planner::parse_plan_cost(args.cost).value();
    start = studies::parse_start_extension(args.start).value();
    if (cfg.model.pump.supply_pressure_pa > 0.0) {
      stage_options.cp_supply_pressure_pa = cfg.model.pump.supply_pressure_pa;
    }
    if (cfg.control.activation_speed_m_s > 0.0) {
      stage_options.at_rest_speed_m_s = cfg.control.activation_speed_m_s;
    }
  } catch (const CLI::Error&) {
    throw;
  } catch (...) {
    return input_error_exit("path");
  }
  dp.refinement.passes = args.refine;
  dp.threads = args.threads;
  Progress progress(args.quiet || args.method != "dp");
  dp.progress = [&progress](int done, int all) { progress(done, all); };

  try {
    const planner::StageModel stages(cfg.model, studies::sample_path(*path, args.dt_s),
                                     stage_options);
    double c_lo = 0.0, c_hi = 0.0;
    if (!planner::feasible_extension_range(stages, 0, c_lo, c_hi)) {
      spdlog::error("path: {}: no extension reaches the start point with every joint in range",
                    args.path_file);
      return kExitUsage;
    }
    const double c0 = studies::start_extension(stages, start);
    if (!args.quiet) {
      spdlog::info("planning {} stages of {:.3g} s with {} (cost {})", stages.stages(), args.dt_s,
                   args.method, args.cost);
    }
    const planner::Plan plan = studies::make_plan(stages, args.method, c0, dp);
    if (!plan.ok) {
      spdlog::error("the planner stopped before it finished");
      return kExitRuntime;
    }
    std::ofstream out(args.out_file);
    if (!out) {
      spdlog::error("cannot write {}", args.out_file);
      return kExitRuntime;
    }
    auto traj = studies::to_joint_trajectory(plan, args.path_file);
    input::write_joint_trajectory(out, traj);
    out.close();
    if (!out) {
      spdlog::error("writing {} failed", args.out_file);
      return kExitRuntime;
    }

    const double unit = stage_options.cost == planner::PlanCost::kExtension ? 1.0 : 1e-3;
    const char* unit_name = stage_options.cost == planner::PlanCost::kExtension ? "m^2/s" : "kJ";
    std::printf("craneassist plan: %s on %s\n", args.path_file.c_str(), cfg.model.name.c_str());
    std::printf("  path %.2f s, %.2f m, peak tip speed %.2f m/s: %d stages of %.3g s\n",
                path->duration_s(), path->length_m(), path->peak_speed_m_s(), stages.stages(),
                args.dt_s);
    std::printf(
        "  start: %s feasible extension, cylinder at %.3f m (feasible %.3f to %.3f m of %.3f)\n",
        studies::to_string(start), c0, c_lo, c_hi, stages.c_max());
    std::printf("  method %s, cost %s: %.4g %s", plan.method.c_str(), args.cost.c_str(),
                plan.total_cost * unit, unit_name);
    if (plan.penalised_stages > 0) {
      std::printf(", LIMITS VIOLATED in %d stages (penalty %.4g)\n", plan.penalised_stages,
                  plan.total_penalty);
    } else {
      std::printf(", every cylinder limit respected\n");
    }
    if (args.method == "dp") {
      std::printf(
          "  grid %d x %d x %d, %d refinement passes (%d used), %s threads: backward %.1f s, "
          "forward %.2f s\n",
          dp.grid.positions, dp.grid.velocities, dp.grid.controls, dp.refinement.passes,
          plan.refinement_passes, args.threads > 0 ? std::to_string(args.threads).c_str() : "all",
          plan.backward_s, plan.forward_s);
      std::printf("  memory: cost-to-go table %.1f MB, process peak %.1f MB\n",
                  static_cast<double>(plan.table_bytes) / 1e6, peak_memory_mb());
    }
    // The same motion judged by the energy costs.
    std::printf("  the plan's model energy:");
    for (auto cost : {planner::PlanCost::kLoadSensing, planner::PlanCost::kConstantPressure,
                      planner::PlanCost::kActuatorEnergy}) {
      planner::StageModelOptions o = stage_options;
      o.cost = cost;
      const planner::StageModel judge(cfg.model, stages.samples(), o);
      planner::Plan copy = plan;
      planner::evaluate_plan(judge, copy);
      std::printf(" %s %.1f kJ", planner::to_string(cost), copy.total_cost / 1e3);
    }
    std::printf("\n  wrote %s (%zu samples); run it: craneassist replay --trajectory %s\n",
                args.out_file.c_str(), traj.size(), args.out_file.c_str());
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace craneassist::cli
