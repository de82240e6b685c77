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
  if (run.scaling != control::ScalingMode::kFull) {
    name += std::string("_scaling-") + control::to_string(run.scaling);
  }
  if (run.sway_damping.has_value() && !*run.sway_damping) name += "_undamped";
  if (!resolution.empty()) name += "_" + resolution;
  return name + ".csv";
}

// Runs that are another run's baseline (the same replay, pose and load with flow prescaling
// only and no sway damping): what craneassist changes against it, per pair.
template <class Done>
void print_baseline_comparison(const std::vector<Done>& done) {
  const auto is_baseline = [](const offline::SuiteRun& r) {
    return r.scaling == control::ScalingMode::kFlowOnly && r.sway_damping.has_value() &&
           !*r.sway_damping;
  };
  const auto change = [](double ours, double base) {
    return base > 0.0 ? 100.0 * (ours / base - 1.0) : 0.0;
  };
  bool header = false;
  for (const auto& b : done) {
    if (!is_baseline(*b.run)) continue;
    for (const auto& d : done) {
      if (&d == &b || is_baseline(*d.run) || !d.run->same_motion(*b.run)) continue;
      if (!header) {
        std::printf("    against the flow-only baseline (scaling flow, no sway damping):\n");
        header = true;
      }
      const auto& o = d.summary;
      const auto& base = b.summary;
      std::printf("      %s: energy %+.0f %%, peak power %+.0f %%, peak swing %+.0f %%",
                  d.run->name().c_str(), change(o.energy_j, base.energy_j),
                  change(o.peak_power_w, base.peak_power_w),
                  change(o.swing.peak_deg, base.swing.peak_deg));
      if (o.waits.waits > 0 && base.waits.waits > 0) {
        std::printf(
            ", residual swing %+.0f %%, cycle time %+.1f %% (%.1f s against %.1f s; waits %.1f s "
            "against %.1f s, %ld and %ld timed out)",
            change(o.waits.residual_swing_deg, base.waits.residual_swing_deg),
            change(o.cycle_time_s, base.cycle_time_s), o.cycle_time_s, base.cycle_time_s,
            o.waits.total_s, base.waits.total_s, o.waits.timed_out, base.waits.timed_out);
      }
      std::printf(", overload cycles %ld against %ld\n", o.load.overload_cycles,
                  base.load.overload_cycles);
    }
  }
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
  std::printf("    %-*s %6s %10s %10s %9s %9s %11s %8s  %s\n", width, "run", "stalls", "lateral",
              "peak power", "dir. err", "energy", "swing", "cycle", "result");
  int missed = 0;
  struct Done {
    const offline::SuiteRun* run;
    control::RunSummary summary;
  };
  std::vector<Done> done;
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
    // The swing: its peak, and with waits the residual swing (from 1 s into a wait).
    char swing[32] = "-";
    if (s.swing.measured && std::isfinite(s.waits.residual_swing_deg)) {
      std::snprintf(swing, sizeof swing, "%.1f/%.1f deg", s.swing.peak_deg,
                    s.waits.residual_swing_deg);
    } else if (s.swing.measured) {
      std::snprintf(swing, sizeof swing, "%.1f deg", s.swing.peak_deg);
    }
    char cycle[32] = "-";
    if (s.waits.waits > 0) std::snprintf(cycle, sizeof cycle, "%.1f s", s.cycle_time_s);
    std::printf("    %-*s %6d %10s %6.2f Pmax %5.2f deg %6.1f kJ %11s %8s  %s\n", width,
                run.name().c_str(), s.feel.stall_events, lateral, s.peak_power_w / out.p_max_w,
                s.max_direction_error_deg, s.energy_j / 1e3, swing, cycle,
                out.ok() ? "ok" : "MISSED");
    for (const auto& m : out.missed) std::printf("      missed: %s\n", m.c_str());
    missed += !out.ok();
    energy_j += s.energy_j;
    ++runs;
    done.push_back({&run, s});
  }
  print_baseline_comparison(done);
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
