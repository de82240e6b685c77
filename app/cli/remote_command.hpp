// `craneassist remote`: the remote operator's console (docs/remote-commands.md). Publishes
// OperatorCommand on craneassist/operator_command at a fixed rate with the operator's DDS
// Security identity (commands.security of --telemetry-config FILE), from the terminal's keyboard
// (crane-frame axes: the console does not know the tip) or from a replay file. --insecure sends
// without DDS Security, only to show that such a participant cannot command the crane.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace craneassist::cli {

struct RemoteArgs {
  std::string config_file;    // --telemetry-config: the operator's DDS settings and identity
  std::optional<int> domain;  // overrides the settings' domain_id
  std::string replay_file;    // empty: the keyboard
  std::string joystick_file;  // keyboard speeds and hold times; empty: the embedded default
  double duration_s = 0.0;    // 0: keyboard until q; replay: its length
  double rate_hz = 50.0;
  double wait_s = 5.0;  // replay: longest wait for a crane's reader before playing anyway
  std::string sender;   // empty: USER@host
  bool insecure = false;
};

CLI::App* add_remote_command(CLI::App& cli, RemoteArgs& args);
int run_remote_command(const RemoteArgs& args);

}  // namespace craneassist::cli
