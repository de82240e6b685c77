#include "calibrate_command.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <fstream>

#include "crane_options.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/valve_table.hpp"
#include "craneassist/offline/calibration.hpp"
#include "exit_codes.hpp"

namespace craneassist::cli {

CLI::App* add_calibrate_command(CLI::App& cli, CalibrateArgs& args) {
  auto* cmd = cli.add_subcommand(
      "calibrate",
      "Sweep the valve command of each section on the simulator (both directions, from "
      "mid-stroke), measure the steady cylinder velocities and write the fitted monotone "
      "velocity-vs-command tables as a YAML block for hydraulics.valves (docs/valves.md)");
  add_config_option(*cmd, args.config_file);
  cmd->add_option("--section", args.section,
                  "Section to calibrate: a joint index 0..n-1, a joint name, or all")
      ->capture_default_str();
  cmd->add_option("--out", args.out_file, "YAML block with the fitted tables")
      ->capture_default_str();
  cmd->add_option("--log", args.log_file, "Sweep log CSV (every control cycle of every level)")
      ->capture_default_str();
  cmd->add_flag("--quiet", args.quiet, "Print nothing but errors");
  return cmd;
}

int run_calibrate_command(const CalibrateArgs& args) {
  config::CraneConfig cfg;
  try {
    cfg = load_crane(args.config_file);
  } catch (const config::ConfigError& e) {
    spdlog::error("config: {}", e.what());
    return kExitUsage;
  }
  const auto& model = cfg.model;
  std::vector<int> sections;
  if (args.section == "all") {
    for (int i = 0; i < model.dof(); ++i) sections.push_back(i);
  } else {
    for (int i = 0; i < model.dof(); ++i) {
      if (model.joints[static_cast<std::size_t>(i)].name == args.section ||
          std::to_string(i) == args.section) {
        sections.push_back(i);
      }
    }
    if (sections.empty()) {
      throw CLI::ValidationError("--section", "expected all, a joint index 0.." +
                                                  std::to_string(model.dof() - 1) +
                                                  " or a joint name, got '" + args.section + "'");
    }
  }

  const offline::CalibrationOptions options;
  std::vector<offline::SweepLogRow> log;
  std::vector<offline::SectionCalibration> results;
  if (!args.quiet) {
    std::printf(
        "craneassist calibrate: %s on the simulator, %zu levels x 2 directions per section\n",
        model.name.c_str(), options.levels.size());
    std::printf("  %-10s %9s %9s %11s %11s %7s\n", "section", "dead -", "dead +", "v_max -",
                "v_max +", "points");
  }
  for (int i : sections) {
    results.push_back(offline::calibrate_section(cfg, i, options, &log));
    const auto& r = results.back();
    if (const std::string why = dynamics::check_valve_table(r.table); !why.empty()) {
      spdlog::error("section {}: the sweep gives no usable table: {}",
                    model.joints[static_cast<std::size_t>(i)].name, why);
      return kExitRuntime;
    }
    if (!args.quiet) {
      std::printf("  %-10s %9.3f %9.3f %7.3f m/s %7.3f m/s %7zu\n",
                  model.joints[static_cast<std::size_t>(i)].name.c_str(), r.dead_band_retract,
                  r.dead_band_extend, r.max_retract_m_s, r.max_extend_m_s, r.table.command.size());
    }
  }

  std::ofstream log_out(args.log_file);
  if (!log_out) {
    spdlog::error("cannot write {}", args.log_file);
    return kExitRuntime;
  }
  offline::write_sweep_log(log_out, model, log);
  std::ofstream yaml_out(args.out_file);
  if (!yaml_out) {
    spdlog::error("cannot write {}", args.out_file);
    return kExitRuntime;
  }
  yaml_out << offline::valve_tables_yaml(
      model, results,
      "craneassist calibrate: " + model.name +
          ", simulator sweep; paste under hydraulics.valves (docs/valves.md)");
  if (!args.quiet) {
    std::printf("  tables: %s (paste under hydraulics.valves)\n  log: %s (%zu rows)\n",
                args.out_file.c_str(), args.log_file.c_str(), log.size());
  }
  return kExitOk;
}

}  // namespace craneassist::cli
