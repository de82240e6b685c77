#include "suite_command.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "crane_options.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/offline/scenario_suite.hpp"
#include "exit_codes.hpp"

namespace craneassist::cli {
namespace {

constexpr int kExitTargetsMissed = 1;

std::string log_name(const offline::SuiteRun& run, const std::string& resolution) {
  std::string name = std::filesystem::path(run.replay_text).stem().string() + "_" + run.pose;
  if (!resolution.empty()) name += "_" + resolution;
  return name + ".csv";
}

// One resolution over the suite: a table row per run. Returns the number of runs that missed a
// target; adds the pump energy.
int run_one_resolution(const offline::Suite& suite, const config::CraneConfig& cfg,
                       const std::string& resolution, const SuiteArgs& args, double& energy_j,
                       int& runs) {
  config::CraneConfig shown = cfg;
  if (!resolution.empty()) config::set_resolution(shown, resolution);
  std::printf("  resolution %s\n", config::resolution_description(shown).c_str());
  int width = 3;  // the run names' column, as wide as the longest
  for (const auto& run : suite.runs) width = std::max(width, static_cast<int>(run.name().size()));
  std::printf("    %-*s %6s %10s %10s %9s %9s  %s\n", width, "run", "stalls", "lateral",
              "peak power", "dir. err", "energy", "result");
  int missed = 0;
  for (const auto& run : suite.runs) {
    if (!args.only.empty() && run.name().find(args.only) == std::string::npos) continue;
    const std::filesystem::path log =
        args.log_dir.empty() ? std::filesystem::path()
                             : std::filesystem::path(args.log_dir) / log_name(run, resolution);
    const auto out = offline::run_suite_run(cfg, run, resolution, log);
    const auto& s = out.summary;
    char lateral[32] = "-";
    if (s.feel.one_line)
      std::snprintf(lateral, sizeof lateral, "%.3f m/s", s.feel.lateral_peak_m_s);
    std::printf("    %-*s %6d %10s %6.2f Pmax %5.2f deg %6.1f kJ  %s\n", width, run.name().c_str(),
                s.feel.stall_events, lateral, s.peak_power_w / out.p_max_w,
                s.max_direction_error_deg, s.energy_j / 1e3, out.ok() ? "ok" : "MISSED");
    for (const auto& m : out.missed) std::printf("      missed: %s\n", m.c_str());
    missed += !out.ok();
    energy_j += s.energy_j;
    ++runs;
  }
  return missed;
}

}  // namespace

CLI::App* add_suite_command(CLI::App& cli, SuiteArgs& args) {
  auto* suite = cli.add_subcommand(
      "suite", "Run a scenario suite (e.g. examples/replays/suite.yaml) and check its targets");
  suite->add_option("manifest", args.manifest, "Suite manifest YAML (docs/suite-format.md)")
      ->required()
      ->check(CLI::ExistingFile);
  add_config_option(*suite, args.config_file);
  add_resolution_option(*suite, args.resolution, "for every run (all: the pump energy of each)",
                        true);
  suite->add_option("--log-dir", args.log_dir, "Write each run's per-cycle log into this folder");
  suite->add_option("--only", args.only, "Run only the runs whose name contains this text");
  return suite;
}

int run_suite_command(const SuiteArgs& args) {
  config::CraneConfig cfg;
  offline::Suite suite;
  try {
    cfg = load_crane(args.config_file);
    suite = offline::load_suite(args.manifest);
    offline::check_suite(suite, cfg);
  } catch (const config::ConfigError& e) {
    spdlog::error("{}", e.what());
    return kExitUsage;
  }
  if (!args.log_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(args.log_dir, ec);
    if (ec) {
      spdlog::error("--log-dir: {}: {}", args.log_dir, ec.message());
      return kExitUsage;
    }
  }
  std::vector<std::string> resolutions;
  if (args.resolution == "all") {
    resolutions = names_of(dynamics::kResolutions);
  } else {
    resolutions = {args.resolution};  // empty: the config's
  }
  std::printf("craneassist suite: %s on %s\n", args.manifest.c_str(), cfg.model.name.c_str());
  struct Total {
    std::string resolution;
    double energy_j;
    int runs, missed;
  };
  std::vector<Total> totals;
  try {
    for (const auto& r : resolutions) {
      double energy = 0.0;
      int runs = 0;
      const int missed = run_one_resolution(suite, cfg, r, args, energy, runs);
      config::CraneConfig shown = cfg;
      if (!r.empty()) config::set_resolution(shown, r);
      totals.push_back({dynamics::to_string(shown.redundancy.resolution), energy, runs, missed});
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  int missed = 0;
  for (const auto& t : totals) {
    std::printf("  %s: %d of %d runs met every target; pump energy over the suite %.1f kJ\n",
                t.resolution.c_str(), t.runs - t.missed, t.runs, t.energy_j / 1e3);
    missed += t.missed;
  }
  if (totals.size() == 1 && totals.front().runs == 0) {
    spdlog::error("--only '{}': no run matches", args.only);
    return kExitUsage;
  }
  std::printf(missed == 0 ? "  every run met its targets\n" : "  %d runs MISSED a target\n",
              missed);
  return missed == 0 ? kExitOk : kExitTargetsMissed;
}

}  // namespace craneassist::cli
