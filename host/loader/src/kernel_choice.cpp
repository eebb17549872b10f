// Which of a plugin's stepping kernels this process uses (plugin_loader.hpp, KernelChoice): the metadata's
// "kernels" object (of a version-4 plugin: its kernel version checked against the one whose arguments version 5
// has), and an instruction set chosen from the processor's features or pinned by NONSEP_INSTRUCTION_SET.
#include <cstdlib>
#include <string>

#include "nonsep/core/kernel/chin_kernel.hpp"
#include "nonsep/core/kernel/processor_levels.hpp"
#include "plugin_internals.hpp"

namespace nonsep::host {

using nlohmann::json;

namespace {

// Whether this processor runs code compiled for `name` (an x86-64 micro-architecture level).
bool processor_runs(const std::string& name) { return processor_runs_level(processor_level(name)); }

}  // namespace

std::string instruction_set_pin() {
  const char* pin = std::getenv("NONSEP_INSTRUCTION_SET");
  if (pin == nullptr || *pin == '\0') return "";
  const std::string name = pin;
  return name == "baseline" ? "x86-64" : name;
}

std::string instruction_set_to_use(const std::vector<std::string>& names) {
  const std::string pin = instruction_set_pin();
  if (pin == "evaluation") return "";
  if (!pin.empty()) return pin;
  for (std::size_t i = names.size(); i-- > 0;)
    if (processor_runs(names[i])) return names[i];
  return "";
}

KernelChoice choose_kernel(const json& metadata, const nonsep_plugin_api& api, unsigned abi_version) {
  KernelChoice choice;
  if (api.chin_steps == nullptr) {
    choice.note = "no stepping kernels: the evaluation path";
    return choice;
  }
  choice.present = true;
  const json& kernels = metadata["kernels"];
  choice.version = abi_version == 4 ? kernels["version"].get<std::uint64_t>() : chin_kernel_version;
  for (const json& name : kernels["instruction_sets"]) {
    choice.instruction_sets.push_back(name.get<std::string>());
    choice.usable.push_back(choice.version == chin_kernel_version && processor_runs(choice.instruction_sets.back()));
  }
  if (choice.version != chin_kernel_version) {
    choice.note = "kernel version " + std::to_string(choice.version) + ", this nonsep's is " +
                  std::to_string(chin_kernel_version) + ": the evaluation path (rebuild the plugin to use its kernels)";
    return choice;
  }
  const std::string pin = instruction_set_pin();
  if (pin == "evaluation") {
    choice.note = "NONSEP_INSTRUCTION_SET=evaluation: the evaluation path";
    return choice;
  }
  for (std::size_t i = choice.instruction_sets.size(); i-- > 0;) {
    const std::string& name = choice.instruction_sets[i];
    if (!pin.empty() && name != pin) continue;
    if (!choice.usable[i]) {
      if (!pin.empty())
        throw PluginError("NONSEP_INSTRUCTION_SET=" + pin + " but this processor cannot run it (unset it, or use " +
                          "x86-64, the baseline every x86-64 runs)");
      continue;
    }
    choice.chosen = i;
    choice.note = pin.empty() ? "the widest this processor runs" : "pinned by NONSEP_INSTRUCTION_SET";
    return choice;
  }
  if (pin.empty()) {
    choice.note = "no kernel this processor runs: the evaluation path";
    return choice;
  }
  std::string known;
  for (const auto& name : choice.instruction_sets) known += (known.empty() ? "" : ", ") + name;
  const std::string advice =
      pin == "x86-64"
          ? "; the evaluation path, NONSEP_INSTRUCTION_SET=evaluation, gives the baseline kernel's numbers bit "
            "for bit, or rebuild the plugin with its baseline kernels: nonsep_add_model(... KERNEL_SETS "
            "native+baseline), or all, -DNONSEP_KERNEL_SETS=... for nonsep's own plugins"
          : "; \"baseline\" means x86-64, \"evaluation\" the evaluation path";
  throw PluginError("NONSEP_INSTRUCTION_SET=" + pin + " names no kernel of this plugin (it has " + known + ")" +
                    advice);
}

}  // namespace nonsep::host
