#include "resolution_option.hpp"

#include <vector>

#include "craneassist/config/crane_config.hpp"

namespace craneassist::cli {

CLI::Option* add_resolution_option(CLI::App& command, std::string& value, const std::string& what,
                                   bool allow_all) {
  std::vector<std::string> names = config::resolution_names();
  std::string help =
      "Redundancy resolution " + what +
      ": energy-optimal (min-ls-power with a load-sensing pump, min-flow with a constant-pressure "
      "one), pinv-joint, pinv-actuator, min-flow or min-ls-power";
  if (allow_all) {
    names.insert(names.begin(), "all");
    help += ", or all (each in turn)";
  }
  help += "; default: the config's redundancy.resolution";
  return command.add_option("--resolution", value, help)->check(CLI::IsMember(names));
}

}  // namespace craneassist::cli
