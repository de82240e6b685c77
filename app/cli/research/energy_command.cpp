#include "research/energy_command.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <fstream>

#include "crane_options.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/studies/energy_experiment.hpp"
#include "exit_codes.hpp"
#include "research/plan_command.hpp"

namespace craneassist::cli {

CLI::App* add_energy_command(CLI::App& cli, EnergyArgs& args) {
  auto* energy = cli.add_subcommand(
      "energy",
      "Paper 000's energy experiment in simulation: every resolution on every path, from both "
      "start configurations, with a load-sensing and a constant-pressure pump (docs/energy.md)");
  energy->add_option("--paths", args.path_files, "Tip path files")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  energy->add_option("--out", args.out_file, "Results CSV (one row per run)")
      ->capture_default_str();
  energy->add_option("--grid", args.grid, "DP grid (see plan --grid)")->capture_default_str();
  energy->add_option("--refine", args.refine, "DP refinement passes")
      ->check(CLI::Range(0, 10))
      ->capture_default_str();
  energy->add_option("--threads", args.threads, "Worker threads (0: one per core)")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  add_config_option(*energy, args.config_file);
  energy->add_flag("--quiet", args.quiet, "No progress output");
  return energy;
}

int run_energy_command(const EnergyArgs& args) {
  config::CraneConfig cfg;
  studies::EnergyExperimentOptions options;
  try {
    cfg = load_crane(args.config_file);
    if (!parse_dp_grid(args.grid, options.dp.grid)) {
      throw CLI::ValidationError(
          "--grid", "expected three counts 2..5000 like 356x101x151, got '" + args.grid + "'");
    }
  } catch (const config::ConfigError& e) {
    spdlog::error("config: {}", e.what());
    return kExitUsage;
  }
  for (const auto& f : args.path_files) options.paths.emplace_back(f);
  options.dp.refinement.passes = args.refine;
  options.dp.threads = args.threads;
  if (cfg.model.pump.supply_pressure_pa > 0.0) {
    options.cp_supply_pressure_pa = cfg.model.pump.supply_pressure_pa;
  }
  if (!args.quiet) {
    options.progress = [](const std::string& text) { spdlog::info("{}", text); };
  }
  try {
    const auto runs = studies::run_energy_experiment(cfg, options);
    std::ofstream out(args.out_file);
    studies::write_energy_csv(out, runs);
    out.close();
    if (!out) {
      spdlog::error("writing {} failed", args.out_file);
      return kExitRuntime;
    }
    std::printf("craneassist energy: %zu runs on %s, results in %s\n", runs.size(),
                cfg.model.name.c_str(), args.out_file.c_str());
    std::printf("  %-11s %-9s %-19s %12s %12s\n", "path", "start", "method", "LS energy",
                "CP energy");
    for (std::size_t i = 0; i + 1 < runs.size(); i += 2) {
      std::printf("  %-11s %-9s %-19s %9.1f kJ %9.1f kJ%s\n", runs[i].path.c_str(),
                  runs[i].start.c_str(), runs[i].method.c_str(), runs[i].energy_j / 1e3,
                  runs[i + 1].energy_j / 1e3,
                  runs[i].penalised_stages > 0 ? "  (plan violates limits)" : "");
    }
  } catch (const input::FileError& e) {
    spdlog::error("path: {}", e.what());
    return kExitUsage;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace craneassist::cli
