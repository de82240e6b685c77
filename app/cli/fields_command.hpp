// `craneassist fields`: the field table (control/log_fields.hpp), every per-cycle value the CSV
// log, DDS, Foxglove and MCAP carry, as Markdown (the tables of docs/log-format.md and
// docs/telemetry.md) or as the JSON Schema of one Foxglove/MCAP channel.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace craneassist::cli {

struct FieldsArgs {
  std::string schema;  // a group's JSON Schema (status, hydraulics, ...); empty: the Markdown
};

CLI::App* add_fields_command(CLI::App& cli, FieldsArgs& args);
int run_fields_command(const FieldsArgs& args);

}  // namespace craneassist::cli
