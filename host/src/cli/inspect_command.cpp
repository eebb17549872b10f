// `nonsep inspect PLUGIN [--json] [--check ...]`: a plugin's metadata, and with --check its derivatives against
// finite differences.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <new>
#include <optional>
#include <string>

#include "cli/commands.hpp"
#include "nonsep/core/base/error.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/inspect/plugin_report.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/plugin_loader.hpp"

namespace nonsep::host::cli {

namespace {

using nlohmann::json;

// Thrown for a bad option of the check; the message names the option and what it wants.
struct BadCheckOption : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "LO,HI" with LO < HI, both finite.
std::pair<double, double> parse_box(const std::string& text) {
  const auto comma = text.find(',');
  const auto low = parse_number(text.substr(0, comma == std::string::npos ? 0 : comma));
  const auto high = comma == std::string::npos ? std::nullopt : parse_number(text.substr(comma + 1));
  if (!low || !high || !std::isfinite(*low) || !std::isfinite(*high) || !(*low < *high))
    throw BadCheckOption("--box expects LO,HI with finite numbers LO < HI, such as --box 0.5,2 (found '" + text + "')");
  return {*low, *high};
}

// "name=value": the value as JSON (3, 0.5, true, "text"), or as a string when it is not JSON (--parameter
// kind=fast).
void add_parameter(json& parameters, const std::string& text) {
  const auto equals = text.find('=');
  if (equals == std::string::npos || equals == 0)
    throw BadCheckOption("--parameter expects name=value, such as --parameter dimension=3 (found '" + text + "')");
  const std::string value = text.substr(equals + 1);
  parameters[text.substr(0, equals)] = json::accept(value) ? json::parse(value) : json(value);
}

// The job file, loaded and checked completely; it must use the inspected plugin.
LoadedJob load_job_for(const std::string& option, const std::string& file, const Plugin& plugin) {
  LoadedJob loaded = load_job(file);
  std::error_code error;
  if (!std::filesystem::equivalent(loaded.plugin.path(), plugin.path(), error))
    throw BadCheckOption(option + " " + file + ": the job uses the plugin '" + loaded.plugin.name() + "' (" +
                         loaded.plugin.path().string() + "), not the inspected " + plugin.path().string());
  return loaded;
}

std::string gigabytes(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g GB", bytes / 1e9);
  return text;
}

int check(const Plugin& plugin, const InspectArguments& arguments, std::ostream& out) {
  json parameters = json::object();
  DerivativeCheckSettings settings;
  std::string from;
  if (!arguments.parameters_job.empty()) {
    const LoadedJob loaded = load_job_for("--job", arguments.parameters_job, plugin);
    parameters = loaded.model.parameters();
    from =
        "the parameters of " + arguments.parameters_job + (loaded.job.sweep.empty() ? "" : " (its sweep's first set)");
  }
  for (const auto& text : arguments.parameters) add_parameter(parameters, text);
  if (!arguments.parameters.empty()) from += std::string(from.empty() ? "" : ", ") + "--parameter";
  if (arguments.box) std::tie(settings.box_low, settings.box_high) = parse_box(*arguments.box);
  if (!arguments.points_job.empty()) {
    const InitialStates states = load_job_for("--points-from", arguments.points_job, plugin).job.initial;
    for (std::size_t b = 0; b < states.count; ++b) {
      const auto at = static_cast<std::ptrdiff_t>(b * states.dimension);
      const auto end = static_cast<std::ptrdiff_t>((b + 1) * states.dimension);
      settings.q_points.emplace_back(states.q.begin() + at, states.q.begin() + end);
      settings.p_points.emplace_back(states.p.begin() + at, states.p.begin() + end);
    }
    if (!arguments.box) settings.random_points = 0;  // the job's states only, unless a box is asked for as well
  }
  if (arguments.tolerance) settings.tolerance = *arguments.tolerance;

  const PluginModel model = plugin.create(parameters);
  const std::size_t n = model.dimension();
  const std::string what = "the derivative check of " + plugin.name() + " (dimension " + std::to_string(n) +
                           ", parameters " + model.parameters().dump() + ")";
  // n > 0: the loader refuses an instance of dimension 0 in create() (a PluginError, exit 2).
  const double needed = derivative_check_bytes(n, plugin.has_third_derivatives(), settings);
  const double memory = static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGESIZE));
  if (memory > 0 && needed > memory) {
    std::cerr << "nonsep: " << what << " needs about " << gigabytes(needed) << " of memory, more than this machine's "
              << gigabytes(memory) << " (the Hessians of the finite-difference stencils grow as n^2 per point"
              << (plugin.has_third_derivatives() ? ", n^3 for the third derivatives" : "")
              << "); check a smaller instance of the model (--parameter)\n";
    return to_int(ExitStatus::invalid_input);
  }
  try {
    const DerivativeCheck result = check_derivatives(model, plugin, settings);
    out << "derivative check of " << plugin.name() << " (" << (from.empty() ? "default parameters" : from)
        << ", dimension " << n << "):\n"
        << result.text;
    return to_int(result.passed ? ExitStatus::success : ExitStatus::run_failed);
  } catch (const std::bad_alloc&) {
    std::cerr << "nonsep: " << what << " ran out of memory (its buffers grow as n^2 per sample point"
              << (plugin.has_third_derivatives() ? ", n^3 for the third derivatives" : "")
              << "); check a smaller instance of the model (--parameter) or fewer points\n";
    return to_int(ExitStatus::invalid_input);
  }
}

}  // namespace

int command_inspect(const InspectArguments& arguments) {
  std::optional<Plugin> plugin;
  try {
    plugin = load_plugin(arguments.name, std::filesystem::current_path());
  } catch (const PluginError& error) {
    std::cerr << "nonsep: " << error.what() << "\n";
    return to_int(ExitStatus::invalid_input);
  }
  if (arguments.as_json)
    std::cout << plugin->metadata().dump(2) << "\n";
  else
    std::cout << describe_plugin(*plugin);
  if (!arguments.as_json) {
    try {
      std::cout << describe_derivative_costs(*plugin, plugin->create(json::object()));
    } catch (const std::exception& error) {
      std::cout << "  cost per call: not measured (no instance at the default parameters: " << error.what() << ")\n";
    }
  }
  if (!arguments.check) return to_int(ExitStatus::success);
  try {
    return check(*plugin, arguments, arguments.as_json ? std::cerr : std::cout);
  } catch (const BadCheckOption& error) {
    std::cerr << "nonsep: inspect --check: " << error.what() << "\n";
    return to_int(ExitStatus::invalid_input);
  } catch (const InvalidJob& error) {
    return report_invalid_job(error);
  } catch (const PluginError& error) {
    std::cerr << "nonsep: " << error.what() << "\n";
    return to_int(ExitStatus::invalid_input);
  } catch (const ModelError& error) {
    std::cerr << "nonsep: derivative check failed: the plugin could not evaluate: " << error.what() << "\n";
    return to_int(ExitStatus::run_failed);
  }
}

}  // namespace nonsep::host::cli
