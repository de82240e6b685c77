#include "fields_command.hpp"

#include <cstdio>
#include <vector>

#include "craneassist/control/log_fields.hpp"
#include "exit_codes.hpp"

namespace craneassist::cli {

CLI::App* add_fields_command(CLI::App& cli, FieldsArgs& args) {
  auto* fields = cli.add_subcommand(
      "fields",
      "Print the field table: every per-cycle value of the CSV log, DDS, Foxglove and MCAP "
      "(Markdown; docs/log-format.md)");
  std::vector<std::string> groups;
  for (const control::FieldGroup g : control::kFieldGroups) groups.emplace_back(to_string(g));
  fields
      ->add_option("--schema", args.schema,
                   "Print the JSON Schema of one group's channel (/craneassist/GROUP) instead")
      ->check(CLI::IsMember(groups));
  return fields;
}

int run_fields_command(const FieldsArgs& args) {
  if (args.schema.empty()) {
    std::fputs(control::fields_markdown().c_str(), stdout);
    return kExitOk;
  }
  for (const control::FieldGroup g : control::kFieldGroups) {
    if (args.schema == to_string(g)) std::printf("%s\n", control::group_json_schema(g).c_str());
  }
  return kExitOk;
}

}  // namespace craneassist::cli
