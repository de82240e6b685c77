// The secure participants of the DDS command input (internal to the dds module): what is
// missing from a set of DDS Security files, for the error messages of the command source and
// the command writer.
#pragma once

#include <string>

#include "craneassist/config/telemetry_config.hpp"

namespace craneassist::dds {

// "commands.security.identity_ca, commands.security.permissions not given", or "" when every
// file is given.
inline std::string missing_security_files(const config::SecurityFiles& s) {
  const std::string missing = s.missing("commands.security.");
  return missing.empty() ? missing : missing + " not given";
}

}  // namespace craneassist::dds
