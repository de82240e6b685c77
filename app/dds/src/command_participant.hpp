// The secure participants of the DDS command input (internal to the dds module): what is
// missing from a set of DDS Security files, for the error messages of the command source and
// the command writer.
#pragma once

#include <filesystem>
#include <string>
#include <utility>

#include "craneassist/config/telemetry_config.hpp"

namespace craneassist::dds {

// "commands.security.identity_ca, commands.security.permissions not given", or "" when every
// file is given.
inline std::string missing_security_files(const config::SecurityFiles& s) {
  const std::pair<const char*, const std::string*> files[] = {
      {"identity_ca", &s.identity_ca}, {"identity_certificate", &s.identity_certificate},
      {"private_key", &s.private_key}, {"permissions_ca", &s.permissions_ca},
      {"governance", &s.governance},   {"permissions", &s.permissions}};
  std::string missing;
  for (const auto& [name, path] : files) {
    if (!path->empty()) continue;
    missing +=
        (missing.empty() ? "commands.security." : ", commands.security.") + std::string(name);
  }
  return missing.empty() ? missing : missing + " not given";
}

// make_participant() hands Fast DDS "file:" + path, but Fast DDS 2.9 takes only "file://PATH"
// (it strips 7 characters): "//" before an absolute path makes "file:///abs/path", and keeps
// working should the prefix become "file://" ("file://///abs/path" is the same path).
inline config::SecurityFiles with_file_uri_paths(config::SecurityFiles s) {
  for (std::string* p : {&s.identity_ca, &s.identity_certificate, &s.private_key, &s.permissions_ca,
                         &s.governance, &s.permissions}) {
    if (!p->empty()) *p = "//" + std::filesystem::absolute(*p).lexically_normal().string();
  }
  return s;
}

}  // namespace craneassist::dds
