// `craneassist suite MANIFEST`: run a scenario suite (examples/replays/suite.yaml) on the simulated
// crane, print each run's operator-feel figures against its targets, and the pump energy over the
// suite per resolution (docs/suite-format.md, docs/scaling.md#operator-feel); with --variants the
// whole suite on every machine variant and a robustness matrix (docs/valves.md).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace craneassist::cli {

struct SuiteArgs {
  std::string manifest;
  std::string config_file;  // empty: the embedded reference crane
  std::string resolution;   // empty: the config's; a name, or "all"
  std::string log_dir;      // empty: no logs
  std::string only;         // run only the runs whose name contains this
  std::string variants;     // machine variants file (empty: the config's machine only)
  std::string matrix_csv;   // one row per variant, resolution and run (empty: none)
  // Before each variant's runs, calibrate its valves on the simulated machine (the sweep of
  // craneassist calibrate) and run with the tables and spool dynamics found.
  bool calibrated = false;
};

CLI::App* add_suite_command(CLI::App& cli, SuiteArgs& args);
// 0: every run met its targets; 1: some missed; 2: a bad manifest, config or option; 3: a failure
// during a run.
int run_suite_command(const SuiteArgs& args);

}  // namespace craneassist::cli
