#include "suite_command.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "crane_options.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/machine_deviation.hpp"
#include "craneassist/dynamics/valve_table.hpp"
#include "craneassist/offline/calibration.hpp"
#include "craneassist/offline/scenario_suite.hpp"
#include "exit_codes.hpp"

namespace craneassist::cli {
namespace {

constexpr int kExitTargetsMissed = 1;

// A variant's log folder: its name with anything but letters, digits, '.', '-' as '_'.
std::string variant_folder(const std::string& name) {
  std::string out = name;
  for (char& c : out) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-')) c = '_';
  }
  return out;
}

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

// One row of the robustness matrix (--matrix): a run on one machine variant.
struct MatrixRow {
  std::string variant, resolution, run;
  control::RunSummary summary;
  bool one_line = false;
  std::size_t missed = 0;
};

// The variant's worst figures over its runs, one line.
void print_variant_line(const std::string& variant, const std::vector<MatrixRow>& rows) {
  double p95 = 0.0, max_dir = 0.0, lateral = 0.0;
  long stalls = 0, timeouts = 0;
  int runs = 0, missed = 0;
  for (const auto& r : rows) {
    if (r.variant != variant) continue;
    const auto& s = r.summary;
    p95 = std::max(p95, s.p95_direction_error_deg);
    max_dir = std::max(max_dir, s.max_direction_error_deg);
    if (r.one_line) lateral = std::max(lateral, s.feel.lateral_peak_m_s);
    stalls += s.feel.stall_events;
    timeouts += s.stop.timeouts;
    ++runs;
    missed += r.missed > 0;
  }
  std::printf("    %-28s %9.2f %9.2f %9.3f %7ld %9ld %5d/%d\n", variant.c_str(), p95, max_dir,
              lateral, stalls, timeouts, runs - missed, runs);
}

bool write_matrix(const std::string& path, const std::vector<MatrixRow>& rows) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  std::fprintf(f,
               "variant,resolution,run,direction_p95_deg,direction_max_deg,direction_rms_deg,"
               "lateral_peak_m_s,stall_events,stops,stop_timeouts,tip_speed_at_neutral_m_s,"
               "peak_power_w,energy_j,missed\n");
  for (const auto& r : rows) {
    const auto& s = r.summary;
    std::fprintf(f, "\"%s\",%s,\"%s\",%.3f,%.3f,%.3f,", r.variant.c_str(), r.resolution.c_str(),
                 r.run.c_str(), s.p95_direction_error_deg, s.max_direction_error_deg,
                 s.rms_direction_error_deg);
    if (r.one_line) {
      std::fprintf(f, "%.4f,", s.feel.lateral_peak_m_s);
    } else {
      std::fprintf(f, ",");
    }
    std::fprintf(f, "%d,%ld,%ld,%.4f,%.0f,%.0f,%zu\n", s.feel.stall_events, s.stop.stops,
                 s.stop.timeouts, s.stop.max_tip_speed_at_neutral_m_s, s.peak_power_w, s.energy_j,
                 r.missed);
  }
  return std::fclose(f) == 0;
}

// One resolution over the suite: a table row per run. Returns the number of runs that missed a
// target; adds the pump energy and the matrix rows.
int run_one_resolution(const offline::Suite& suite, const config::CraneConfig& cfg,
                       const offline::SuiteVariant* variant, const std::string& resolution,
                       const SuiteArgs& args, double& energy_j, int& runs,
                       std::vector<MatrixRow>& matrix) {
  config::CraneConfig shown = cfg;
  if (!resolution.empty()) config::set_resolution(shown, resolution);
  std::printf("  %s%sresolution %s\n", variant ? "machine " : "",
              variant ? (variant->name + ", ").c_str() : "",
              config::resolution_description(shown).c_str());
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
    std::filesystem::path log;
    if (!args.log_dir.empty()) {
      log = std::filesystem::path(args.log_dir);
      if (variant) {
        log /= variant_folder(variant->name);
        std::error_code ec;
        std::filesystem::create_directories(log, ec);  // a failure shows when the log opens
      }
      log /= log_name(run, resolution);
    }
    const auto out = offline::run_suite_run(
        cfg, run, variant ? variant->targets : offline::SuiteTargets{}, resolution, log);
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
    matrix.push_back({variant ? variant->name : std::string("config"),
                      dynamics::to_string(shown.redundancy.resolution), run.name(), s,
                      s.feel.one_line, out.missed.size()});
    for (const auto& m : out.missed) std::printf("      missed: %s\n", m.c_str());
    missed += !out.ok();
    energy_j += s.energy_j;
    ++runs;
    done.push_back({&run, s});
  }
  print_baseline_comparison(done);
  return missed;
}

// The variant's machine with the controller's valve model calibrated on it: every section swept
// as `craneassist calibrate` does on the simulator, its table and (where identified) its spool
// delay and time constant put into the model. Prints what was found against the machine's truth.
config::CraneConfig calibrated_on(const config::CraneConfig& machine, const std::string& name) {
  config::CraneConfig out = machine;
  auto& model = out.model;
  model.valves.tables.assign(static_cast<std::size_t>(model.dof()), dynamics::ValveTable{});
  const offline::CalibrationOptions options;
  std::printf("  machine %s: calibrated (found / the machine's)\n", name.c_str());
  for (int i = 0; i < model.dof(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    auto r = offline::calibrate_section(machine, i, options);
    const auto truth = dynamics::machine_valve(machine.model.valves, machine.simulation.valves[k]);
    std::printf("    %-10s dead band %.3f/%.3f / %.3f", model.joints[k].name.c_str(),
                -r.dead_band_retract, r.dead_band_extend, truth.dead_zone);
    if (r.dynamics.identified) {
      offline::apply_dynamics(r.dynamics, r.table);
      std::printf(", delay %.3f / %.3f s, time constant %.3f / %.3f s\n", r.dynamics.delay_s,
                  truth.delay_s, r.dynamics.time_constant_s, truth.time_constant_s);
    } else {
      std::printf(", spool dynamics not identified: %s\n", r.dynamics.why_not.c_str());
    }
    if (dynamics::check_valve_table(r.table).empty()) model.valves.tables[k] = r.table;
  }
  return out;
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
  suite
      ->add_option("--variants", args.variants,
                   "Run the suite on every machine variant of this file "
                   "(craneassist-variants/1; docs/suite-format.md#machine-variants)")
      ->check(CLI::ExistingFile);
  suite->add_flag("--calibrated", args.calibrated,
                  "With --variants: first calibrate each machine's valves on it (the sweep of "
                  "craneassist calibrate) and run with the tables and spool dynamics found");
  suite->add_option("--matrix", args.matrix_csv,
                    "Write one CSV row per variant, resolution and run (the robustness matrix)");
  return suite;
}

int run_suite_command(const SuiteArgs& args) {
  config::CraneConfig cfg;
  offline::Suite suite;
  std::vector<offline::SuiteVariant> variants;
  try {
    cfg = load_crane(args.config_file);
    suite = offline::load_suite(args.manifest);
    offline::check_suite(suite, cfg);
    if (!args.variants.empty()) variants = offline::load_variants(args.variants, cfg);
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
  std::vector<MatrixRow> matrix;
  std::vector<const offline::SuiteVariant*> machines;
  for (const auto& v : variants) machines.push_back(&v);
  if (machines.empty()) machines.push_back(nullptr);  // the config's machine
  try {
    for (const auto* variant : machines) {
      config::CraneConfig machine_cfg = variant ? variant->apply(cfg) : cfg;
      if (args.calibrated)
        machine_cfg = calibrated_on(machine_cfg, variant ? variant->name : "config");
      for (const auto& r : resolutions) {
        double energy = 0.0;
        int runs = 0;
        const int missed =
            run_one_resolution(suite, machine_cfg, variant, r, args, energy, runs, matrix);
        config::CraneConfig shown = cfg;
        if (!r.empty()) config::set_resolution(shown, r);
        totals.push_back({(variant ? variant->name + ", " : std::string()) +
                              dynamics::to_string(shown.redundancy.resolution),
                          energy, runs, missed});
      }
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  if (!variants.empty()) {
    std::printf("  robustness matrix (worst over the runs; lateral: one-line runs, over 50 ms)\n");
    std::printf("    %-28s %9s %9s %9s %7s %9s %7s\n", "machine", "p95 deg", "max deg", "lat. m/s",
                "stalls", "stop t/o", "ok");
    for (const auto& v : variants) print_variant_line(v.name, matrix);
  }
  if (!args.matrix_csv.empty() && !write_matrix(args.matrix_csv, matrix)) {
    spdlog::error("--matrix: cannot write {}", args.matrix_csv);
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
