// craneassist: boom-tip control for hydraulic cranes. main() only dispatches: each subcommand
// has its own file (add_*_command registers its options, run_*_command runs it), and every error
// that leaves a subcommand takes the one path below: a usage error exits 2 with CLI11's message,
// anything else is logged and exits 3 (docs: README.md#exit-codes).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "calibrate_command.hpp"
#include "can_commands.hpp"
#include "can_tool_command.hpp"
#include "exit_codes.hpp"
#include "fields_command.hpp"
#include "replay_command.hpp"
#include "research/bound_command.hpp"
#include "research/energy_command.hpp"
#include "research/experiment_command.hpp"
#include "research/follow_command.hpp"
#include "research/plan_command.hpp"
#include "research/polytope_command.hpp"
#include "research/ptp_command.hpp"
#include "sim_command.hpp"
#include "suite_command.hpp"
#include "urdf_command.hpp"
#if CRANEASSIST_WITH_DDS
#include "dds_commands.hpp"
#include "remote_command.hpp"
#endif

namespace {

using namespace craneassist::cli;

struct Subcommand {
  CLI::App* app;
  std::function<int()> run;
};

// Registers a subcommand: its arguments live as long as the program, its options bind to them.
template <class Args>
void add(std::vector<Subcommand>& commands, CLI::App& cli,
         CLI::App* (*add_command)(CLI::App&, Args&), int (*run_command)(const Args&)) {
  auto args = std::make_shared<Args>();
  CLI::App* app = add_command(cli, *args);
  commands.push_back({app, [args, run_command] { return run_command(*args); }});
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"craneassist: boom-tip control for hydraulic cranes"};
  cli.set_version_flag("--version", "craneassist 0.1.0");
  cli.require_subcommand(1);
  spdlog::set_pattern("craneassist: %^%l%$: %v");

  std::vector<Subcommand> commands;
  add(commands, cli, add_replay_command, run_replay_command);
  add(commands, cli, add_emulate_command, run_emulate_command);
  add(commands, cli, add_can_tool_command, run_can_tool_command);
  add(commands, cli, add_calibrate_command, run_calibrate_command);
  add(commands, cli, add_sim_command, run_sim_command);
  add(commands, cli, add_suite_command, run_suite_command);
  add(commands, cli, add_urdf_command, run_urdf_command);
  add(commands, cli, add_fields_command, run_fields_command);
  // The papers' studies and offline analyses (research/, docs/research.md): craneassist research
  // <study>.
  CLI::App* research = cli.add_subcommand(
      "research",
      "The papers' studies and offline analyses: the 2R and energy experiments, "
      "planning, the time-optimal bound, the flow polytope, the crane on wheels, "
      "the MHSB point-to-point planner");
  research->require_subcommand(1);
  add(commands, *research, add_experiment_command, run_experiment_command);
  add(commands, *research, add_energy_command, run_energy_command);
  add(commands, *research, add_plan_command, run_plan_command);
  add(commands, *research, add_bound_command, run_bound_command);
  add(commands, *research, add_polytope_command, run_polytope_command);
  add(commands, *research, add_follow_command, run_follow_command);
  add(commands, *research, add_ptp_command, run_ptp_command);
  // Where the studies were before: a hidden command that says where they are now (exit 2).
  for (CLI::App* study : research->get_subcommands([](CLI::App*) { return true; })) {
    CLI::App* moved = cli.add_subcommand(study->get_name(), "")->group("");
    moved->set_help_flag();  // --help too says where the study is now
    moved->allow_extras()->prefix_command();
    const std::string name = study->get_name();
    commands.push_back({moved, [name] {
                          spdlog::error(
                              "`craneassist {0}` is now `craneassist research {0}` "
                              "(docs/research.md)",
                              name);
                          return kExitUsage;
                        }});
  }
#if CRANEASSIST_WITH_DDS  // a build without DDS (CRANEASSIST_DDS=OFF) has none of these
  add(commands, cli, add_remote_command, run_remote_command);
  add(commands, cli, add_echo_command, run_echo_command);
  add(commands, cli, add_dashboard_command, run_dashboard_command);
  add(commands, cli, add_web_watch_command, run_web_watch_command);
#endif

  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every usage error exits 2, like a bad config or replay.
    return cli.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  for (const Subcommand& c : commands) {
    if (!*c.app) continue;
    try {
      return c.run();
    } catch (const CLI::Error& e) {  // a value the parser could not check (a quantity, a pose)
      cli.exit(e);
      return kExitUsage;
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
      return kExitRuntime;
    }
  }
  return kExitUsage;
}
