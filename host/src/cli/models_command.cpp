// `nonsep models`: the plugins on the search path, one line each (failures with their error).
#include <iostream>

#include "cli/commands.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/inspect/plugin_report.hpp"
#include "nonsep/host/plugin_loader.hpp"

namespace nonsep::host::cli {

int command_models() {
  const auto discovered = discover_plugins();
  for (const auto& entry : discovered) std::cout << describe_discovered(entry) << "\n";
  if (discovered.empty()) {
    std::cerr << "nonsep: no plugins found; searched:";
    for (const auto& directory : plugin_search_path()) std::cerr << " " << directory.string();
    std::cerr << "\n";
  }
  return to_int(ExitStatus::success);
}

}  // namespace nonsep::host::cli
