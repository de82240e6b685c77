#include "calibrate_command.hpp"

#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>

#include "crane_options.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/valve_table.hpp"
#include "craneassist/offline/calibration.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"

namespace craneassist::cli {
namespace {

std::atomic<bool> g_stop{false};

extern "C" void on_calibrate_stop_signal(int) {
  g_stop.store(true);
}

// SIGINT and SIGTERM stop a sweep on a machine (the spools ramp to neutral, then the valves
// block) while it runs; the defaults after.
class StopOnSignal {
 public:
  StopOnSignal() {
    g_stop.store(false);
    struct sigaction sa = {};
    sa.sa_handler = on_calibrate_stop_signal;
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
  }
  ~StopOnSignal() {
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
  }
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;
};

// The sections --section names, in joint order. Throws CLI::ValidationError.
std::vector<int> chosen_sections(const dynamics::CraneModel& model, const std::string& section) {
  std::vector<int> sections;
  for (int i = 0; i < model.dof(); ++i) {
    if (section == "all" || model.joints[static_cast<std::size_t>(i)].name == section ||
        std::to_string(i) == section) {
      sections.push_back(i);
    }
  }
  if (sections.empty()) {
    throw CLI::ValidationError("--section", "expected all, a joint index 0.." +
                                                std::to_string(model.dof() - 1) +
                                                " or a joint name, got '" + section + "'");
  }
  return sections;
}

void print_section(const dynamics::CraneModel& model, const offline::SectionCalibration& r) {
  std::printf("  %-10s %9.3f %9.3f %7.3f m/s %7.3f m/s %7zu",
              model.joints[static_cast<std::size_t>(r.section)].name.c_str(), r.dead_band_retract,
              r.dead_band_extend, r.max_retract_m_s, r.max_extend_m_s, r.table.command.size());
  const auto& d = r.dynamics;
  if (d.identified) {
    std::printf("   %6.3f s %7.3f s %5.1f ms", d.delay_s, d.time_constant_s, 1e3 * d.residual_s);
  } else {
    std::printf("   %6s   %7s   %6s", "-", "-", "-");
  }
}

// The sections whose spool dynamics were not identified, each with the reason (the table is
// still written; the controller keeps hydraulics.valves' time_constant and delay for them).
void print_unidentified(const dynamics::CraneModel& model,
                        const std::vector<offline::SectionCalibration>& results) {
  for (const auto& r : results) {
    if (r.dynamics.identified) continue;
    spdlog::warn("section {}: spool delay and time constant not identified: {}",
                 model.joints[static_cast<std::size_t>(r.section)].name, r.dynamics.why_not);
  }
}

// Whether the section's sweep gives a table the config takes (why not is logged).
bool usable(const dynamics::CraneModel& model, const offline::SectionCalibration& r) {
  if (const std::string why = dynamics::check_valve_table(r.table); !why.empty()) {
    spdlog::error("section {}: the sweep gives no usable table: {}",
                  model.joints[static_cast<std::size_t>(r.section)].name, why);
    return false;
  }
  return true;
}

}  // namespace

CLI::App* add_calibrate_command(CLI::App& cli, CalibrateArgs& args) {
  auto* cmd = cli.add_subcommand(
      "calibrate",
      "Sweep the valve command of each section on the simulator or on a machine (--backend can; "
      "both directions, each level from mid-stroke), measure the steady cylinder velocities and "
      "identify each spool's delay and time constant from the levels' onsets, and write the "
      "fitted monotone velocity-vs-command tables with them as a YAML block for "
      "hydraulics.valves (docs/valves.md)");
  add_config_option(*cmd, args.config_file);
  add_backend_options(*cmd, args.machine);
  cmd->add_option("--section", args.section,
                  "Section to calibrate: a joint index 0..n-1, a joint name, or all")
      ->capture_default_str();
  cmd->add_option("--levels", args.levels,
                  "Command levels to sweep, each in both directions: a comma list in (0, 1], "
                  "ascending (default: 0.1,0.2,0.3,0.4,0.45,0.5,0.55,0.6,0.65,0.7,0.8,0.9,0.95,1)")
      ->delimiter(',')
      ->check(FiniteRange(0.0, 1.0));
  cmd->add_option("--out", args.out_file, "YAML block with the fitted tables")
      ->capture_default_str();
  cmd->add_option("--log", args.log_file, "Sweep log CSV (every control cycle of every level)")
      ->capture_default_str();
  cmd->add_flag("--quiet", args.quiet, "Print nothing but errors");
  return cmd;
}

int run_calibrate_command(const CalibrateArgs& args) {
  config::CraneConfig cfg;
  MachineInputs machine_inputs;
  std::vector<int> sections;
  offline::CalibrationOptions options;
  try {
    cfg = load_crane(args.config_file);
    apply_backend_options(cfg, args.machine);
    machine_inputs = load_machine_inputs(cfg, args.machine);
    sections = chosen_sections(cfg.model, args.section);
    if (!args.levels.empty()) {
      if (const std::string why = offline::check_levels(args.levels); !why.empty()) {
        throw CLI::ValidationError("--levels", why);
      }
      options.levels = args.levels;
    }
  } catch (...) {
    return input_error_exit("calibrate");
  }
  const auto& model = cfg.model;
  const bool on_machine = uses_can_backend(args.machine, cfg);

  std::vector<offline::SweepLogRow> log;
  std::vector<offline::SectionCalibration> results;
  if (!args.quiet) {
    std::printf("craneassist calibrate: %s on %s, %zu levels x 2 directions per section\n",
                model.name.c_str(), on_machine ? "the machine (can backend)" : "the simulator",
                options.levels.size());
    std::printf("  %-10s %9s %9s %11s %11s %7s %9s %9s %8s\n", "section", "dead -", "dead +",
                "v_max -", "v_max +", "points", "delay", "lag", "misfit");
  }
  int rc = kExitOk;
  if (!on_machine) {
    for (int i : sections) {
      results.push_back(offline::calibrate_section(cfg, i, options, &log));
      if (!usable(model, results.back())) return kExitRuntime;
      if (!args.quiet) {
        print_section(model, results.back());
        std::printf("\n");
      }
    }
  } else {
    // One machine for the whole run: opened (its feedback awaited, then enabled), each section
    // swept in its own loop, then deactivated (every valve to its safe state) and reported.
    try {
      Machine machines;
      if (const int open_rc = machines.open(cfg, args.machine, machine_inputs);
          open_rc != kExitOk) {
        return open_rc;
      }
      offline::MachineSweep sweep;
      {
        const StopOnSignal stop_on_signal;
        for (int i : sections) {
          if (!args.quiet) {
            spdlog::info("sweeping {}: from mid-stroke, {} levels x 2 directions",
                         model.joints[static_cast<std::size_t>(i)].name, options.levels.size());
          }
          sweep =
              offline::calibrate_section_on_machine(cfg, machines.get(), i, options, &g_stop, &log);
          if (sweep.end != offline::SweepEnd::kComplete) break;
          results.push_back(sweep.section);
          if (!usable(model, results.back())) {
            results.pop_back();
            rc = kExitRuntime;
            break;
          }
          if (!args.quiet) {
            print_section(model, results.back());
            std::printf("   in %.0f s\n", sweep.wall_time_s);
            std::fflush(stdout);
          }
        }
      }
      if (machines.finish() != kExitOk) rc = kExitRuntime;  // prints the reason of a fault
      if (sweep.end != offline::SweepEnd::kComplete) {
        spdlog::error("calibration stopped: {}; {} of {} sections calibrated", sweep.reason,
                      results.size(), sections.size());
        rc = kExitRuntime;
      }
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
      return kExitRuntime;
    }
  }

  print_unidentified(model, results);
  std::ofstream log_out(args.log_file);
  if (!log_out) {
    spdlog::error("cannot write {}", args.log_file);
    return kExitRuntime;
  }
  offline::write_sweep_log(log_out, model, log);
  if (!results.empty()) {
    std::ofstream yaml_out(args.out_file);
    if (!yaml_out) {
      spdlog::error("cannot write {}", args.out_file);
      return kExitRuntime;
    }
    yaml_out << offline::valve_tables_yaml(
        model, results,
        "craneassist calibrate: " + model.name +
            (on_machine ? ", machine sweep over CAN" : ", simulator sweep") +
            "; paste under hydraulics.valves (docs/valves.md)");
    if (!args.quiet) {
      std::printf("  tables: %s (paste under hydraulics.valves)\n", args.out_file.c_str());
    }
  }
  if (!args.quiet) std::printf("  log: %s (%zu rows)\n", args.log_file.c_str(), log.size());
  return rc;
}

}  // namespace craneassist::cli
