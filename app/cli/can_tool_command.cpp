#include "can_tool_command.hpp"

#include <filesystem>

#include "can_commands.hpp"
#include "craneassist/can/dbc.hpp"
#include "exit_codes.hpp"

namespace craneassist::cli {

CLI::App* add_can_tool_command(CLI::App& cli, CanToolArgs& args) {
  auto* can = cli.add_subcommand("can", "Tools for the CAN mapping (docs/can.md)");
  can->require_subcommand(1);
  args.dbc = can->add_subcommand(
      "dbc",
      "Write the mapping as a DBC file: every frame craneassist sends and receives, with "
      "scalings, units, cycle times and J1939 attributes, for canmatrix, cantools or SavvyCAN");
  args.dbc
      ->add_option("--mapping", args.mapping_file,
                   "CAN mapping file (default: the embedded config/can/k70m_can.yaml)")
      ->check(CLI::ExistingFile);
  args.dbc->add_option("-o,--output", args.output, "Write to this file (default: standard output)");
  return can;
}

int run_can_tool_command(const CanToolArgs& args) {
  can::CanMapping mapping;
  try {
    mapping = load_mapping_or_default(args.mapping_file);
  } catch (...) {
    return input_error_exit("CAN mapping");
  }
  const std::string title = args.mapping_file.empty()
                                ? std::string("k70m_can.yaml")
                                : std::filesystem::path(args.mapping_file).filename().string();
  return write_output(can::write_dbc(mapping, title), args.output,
                      std::to_string(mapping.joints.size()) + " joints");
}

}  // namespace craneassist::cli
