// The compiler, flags and SDK headers that make formula plugins (plugin_cache.hpp: find_toolchain, kernel_flags).
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <sstream>

#include "nonsep/core/kernel/chin_kernel.hpp"
#include "nonsep/host/formula/plugin_cache.hpp"
#include "nonsep/host/output/content_hash.hpp"
#include "nonsep/host/platform/installation.hpp"

namespace nonsep::host::formula {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* install_hint =
    "formula models are compiled into plugins on first use: install a C++20 compiler (Debian and Ubuntu: apt-get "
    "install g++) or name one in NONSEP_CXX";

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The compiler as an executable file: a path as given, a name looked up in PATH; nothing when absent.
std::optional<fs::path> locate(const std::string& compiler) {
  if (compiler.find('/') != std::string::npos)
    return ::access(compiler.c_str(), X_OK) == 0 ? std::optional<fs::path>(compiler) : std::nullopt;
  const char* path = std::getenv("PATH");
  std::stringstream folders(path ? path : "/usr/local/bin:/usr/bin:/bin");
  for (std::string folder; std::getline(folders, folder, ':');) {
    const fs::path candidate = fs::path(folder.empty() ? "." : folder) / compiler;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return std::nullopt;
}

// The content hash of the SDK a formula plugin is built with: every nonsep header it includes (nonsep/plugin_sdk.hpp
// and, transitively, each "nonsep/..." header it names, found in the include folders in order; by name and content,
// not by folder) and the content of each library it links.
std::string sdk_hash(const std::vector<fs::path>& folders, const std::vector<fs::path>& libraries) {
  static const std::regex include_line(R"(^\s*#\s*include\s*[<"](nonsep/[^>"]+)[>"])");
  std::map<std::string, std::string> headers;
  std::vector<std::string> pending{"nonsep/plugin_sdk.hpp"};
  while (!pending.empty()) {
    const std::string name = pending.back();
    pending.pop_back();
    if (headers.count(name) != 0) continue;
    std::string& text = headers[name];
    std::error_code error;
    for (const auto& folder : folders)
      if (fs::is_regular_file(folder / name, error)) {
        text = read_file(folder / name);
        break;
      }
    std::istringstream lines(text);
    std::smatch match;
    for (std::string line; std::getline(lines, line);)
      if (std::regex_search(line, match, include_line)) pending.push_back(match[1].str());
  }
  std::uint64_t hash = content_hash_start;
  for (const auto& [name, text] : headers) hash = content_hash(text + '\0', content_hash(name + '\0', hash));
  for (const auto& library : libraries) hash = content_hash(read_file(library) + '\0', hash);
  return content_hash_hex(hash);
}

}  // namespace

Toolchain find_toolchain(PluginUse use) {
  const auto data = data_directory();
  const fs::path file = data ? *data / "formula" / "toolchain.json" : fs::path();
  std::error_code error;
  if (!data || !fs::is_regular_file(file, error))
    throw FormulaCompileError("the toolchain file share/nonsep/formula/toolchain.json of this nonsep is missing (" +
                              std::string(data ? "not in " + data->string() : "no share/nonsep found") +
                              "): reinstall nonsep");
  const json description = json::parse(read_file(file), nullptr, false);
  if (!description.is_object() || !description.value("compiler", json()).is_string() ||
      !description.value("flags", json()).is_array() || !description.value("include_directories", json()).is_array() ||
      !description.value("libraries", json()).is_array())
    throw FormulaCompileError("the toolchain file " + file.string() + " is damaged: reinstall nonsep");
  Toolchain toolchain;
  toolchain.compiler = description["compiler"].get<std::string>();
  if (const char* chosen = std::getenv("NONSEP_CXX"); chosen && *chosen) toolchain.compiler = chosen;
  for (const auto& flag : description["flags"]) toolchain.flags.push_back(flag.get<std::string>());
  bool has_sdk = false;
  for (const auto& folder : description["include_directories"]) {
    const fs::path path = (file.parent_path() / folder.get<std::string>()).lexically_normal();
    has_sdk = has_sdk || fs::is_regular_file(path / "nonsep" / "plugin_sdk.hpp", error);
    toolchain.include_directories.push_back(path);
  }
  if (!has_sdk)
    throw FormulaCompileError("the plugin SDK's headers (nonsep/plugin_sdk.hpp) are not in the folders of " +
                              file.string() + ": reinstall nonsep with its headers");
  for (const auto& library : description["libraries"]) {
    if (!library.is_string())
      throw FormulaCompileError("the toolchain file " + file.string() + " is damaged: reinstall nonsep");
    const fs::path path = (file.parent_path() / library.get<std::string>()).lexically_normal();
    if (!fs::is_regular_file(path, error))
      throw FormulaCompileError("the plugin SDK's library " + path.string() + ", named in " + file.string() +
                                ", is missing: reinstall nonsep with its libraries");
    toolchain.libraries.push_back(path);
  }
  const auto compiler = locate(toolchain.compiler);
  if (!compiler)
    throw FormulaCompileError(
        "no C++ compiler: " + toolchain.compiler + " " +
        (toolchain.compiler.find('/') != std::string::npos ? "does not exist or cannot run" : "is not in PATH") + "; " +
        install_hint);
  toolchain.compiler = compiler->string();
  const auto version = run_compiler({toolchain.compiler, "--version"}, compile_time_limit());
  if (version.status != 0)
    throw FormulaCompileError("the compiler " + toolchain.compiler +
                              " does not run (`--version` failed with exit status " + std::to_string(version.status) +
                              ": " + version.output + "); " + install_hint);
  const fs::path resolved = fs::canonical(*compiler, error);
  toolchain.identity = (error ? compiler->string() : resolved.string()) + "\n" + version.output;
  toolchain.sdk_hash = sdk_hash(toolchain.include_directories, toolchain.libraries);
  for (const auto& flag : kernel_flags(use)) toolchain.flags.push_back(flag);
  return toolchain;
}

std::vector<std::string> kernel_flags(PluginUse use) {
  const std::string set = instruction_set_to_use({"x86-64", "x86-64-v3", "x86-64-v4"});
  const int bits = set == "x86-64-v3" ? 1 : set == "x86-64-v4" ? 2 : 0;
  std::vector<std::string> flags{"-DNONSEP_SDK_WIDE_KERNEL_SETS=" + std::to_string(bits)};
  if (use == PluginUse::cache && bits != 0) flags.push_back("-DNONSEP_SDK_BASELINE_KERNELS=0");
  return flags;
}

}  // namespace nonsep::host::formula
