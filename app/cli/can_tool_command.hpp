// `craneassist can ...`: tools for the CAN mapping outside a run. `can dbc` writes the mapping as
// a DBC file (valves/can dbc.hpp, docs/can.md#dbc-files) for canmatrix, cantools, SavvyCAN or a
// machine maker's tool chain.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace craneassist::cli {

struct CanToolArgs {
  CLI::App* dbc = nullptr;   // the `dbc` subcommand, to see whether it was given
  std::string mapping_file;  // empty: the embedded K70M mapping
  std::string output;        // empty: standard output
};

CLI::App* add_can_tool_command(CLI::App& cli, CanToolArgs& args);
int run_can_tool_command(const CanToolArgs& args);

}  // namespace craneassist::cli
