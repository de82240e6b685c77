// `craneassist research polytope`: the flow manipulability polytope of a crane at one pose
// (offline/polytope_report.hpp, docs/polytope.md): its volume, the admissible tip speed along a
// direction over every joint motion and along the controller's resolution, its vertices; a CSV
// of the vertices and a picture (tools/plot_polytope.py, run with python3).
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace craneassist::cli {

struct PolytopeArgs {
  std::string config_file;  // empty: the embedded reference crane
  std::string pose;         // empty: the config's simulation.initial
  std::string direction;    // empty: the task axes both ways
  std::optional<double> speed_m_s;
  std::string resolution;     // empty: the config's
  std::string pump_max_flow;  // empty: the config's
  std::string modes;          // an MHSB arm's mode pattern, e.g. "N-DB-N"; empty: all N
  std::string out;            // CSV of the vertices; empty: none
  std::string plot;           // PNG; empty: none
};

CLI::App* add_polytope_command(CLI::App& cli, PolytopeArgs& args);
int run_polytope_command(const PolytopeArgs& args);

}  // namespace craneassist::cli
