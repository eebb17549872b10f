// `nonsep inspect PLUGIN [--json] [--check]`: a plugin's metadata, and with --check its derivatives against finite
// differences.
#include <iostream>
#include <optional>
#include <string>

#include "cli/commands.hpp"
#include "nonsep/core/error.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/host/plugin_report.hpp"

namespace nonsep::host::cli {

int command_inspect(const std::string& name, bool as_json, bool check) {
  std::optional<Plugin> plugin;
  try {
    plugin = load_plugin(name, std::filesystem::current_path());
  } catch (const PluginError& error) {
    std::cerr << "nonsep: " << error.what() << "\n";
    return to_int(ExitStatus::invalid_input);
  }
  if (as_json)
    std::cout << plugin->metadata().dump(2) << "\n";
  else
    std::cout << describe_plugin(*plugin);
  if (!check) return to_int(ExitStatus::success);
  try {
    const PluginModel model = plugin->create(nlohmann::json::object());
    const DerivativeCheck result = check_derivatives(model, *plugin);
    (as_json ? std::cerr : std::cout) << "derivative check of " << plugin->name() << " (default parameters, dimension "
                                      << model.dimension() << "):\n"
                                      << result.text;
    return to_int(result.passed ? ExitStatus::success : ExitStatus::run_failed);
  } catch (const PluginError& error) {
    std::cerr << "nonsep: " << error.what() << "\n";
    return to_int(ExitStatus::invalid_input);
  } catch (const ModelError& error) {
    std::cerr << "nonsep: derivative check failed: the plugin could not evaluate: " << error.what() << "\n";
    return to_int(ExitStatus::run_failed);
  }
}

}  // namespace nonsep::host::cli
