// Compiling formula models and caching their plugins (plugin_cache.hpp).
#include "nonsep/host/formula/plugin_cache.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "nonsep/core/chin_kernel.hpp"
#include "nonsep/host/formula/cpp_source.hpp"
#include "nonsep/host/output/content_hash.hpp"
#include "nonsep/host/platform/installation.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/plugin_abi.h"

#ifndef NONSEP_VERSION
#error "NONSEP_VERSION must be defined by the build"
#endif

extern char** environ;

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

// Runs argv (no shell) with standard output and error into one pipe; returns the exit status (-1: not started,
// 128 + n: killed by signal n) and at most the last 64 KiB of the output.
std::pair<int, std::string> run_capturing(const std::vector<std::string>& arguments) {
  int pipe_ends[2];
  if (::pipe(pipe_ends) != 0) return {-1, "cannot create a pipe"};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_ends[1], 1);
  posix_spawn_file_actions_adddup2(&actions, pipe_ends[1], 2);
  posix_spawn_file_actions_addclose(&actions, pipe_ends[0]);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  std::vector<char*> argv;
  for (const auto& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);
  pid_t child = 0;
  const int spawned = ::posix_spawnp(&child, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_ends[1]);
  std::string output;
  char buffer[4096];
  for (ssize_t n; (n = ::read(pipe_ends[0], buffer, sizeof buffer)) != 0;) {
    if (n < 0) {
      if (errno == EINTR) continue;
      break;
    }
    output.append(buffer, static_cast<std::size_t>(n));
    if (output.size() > (std::size_t{1} << 16)) output.erase(0, output.size() - (std::size_t{1} << 16));
  }
  ::close(pipe_ends[0]);
  if (spawned != 0) return {-1, std::strerror(spawned)};
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status)) return {128 + WTERMSIG(status), output};
  return {WEXITSTATUS(status), output};
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

// A folder where this process can create files: `folder` (created), or nothing.
bool writable_folder(const fs::path& folder) {
  std::error_code error;
  fs::create_directories(folder, error);
  if (!fs::is_directory(folder, error)) return false;
  std::string probe = (folder / ".write-probe-XXXXXX").string();
  const int descriptor = ::mkstemp(probe.data());
  if (descriptor < 0) return false;
  ::close(descriptor);
  ::unlink(probe.c_str());
  return true;
}

std::string unique_suffix() {
  static std::uint64_t counter = 0;
  return std::to_string(::getpid()) + "-" +
         std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + "-" + std::to_string(++counter);
}

// Whether formula/<key>/ is a complete entry for `source` (plugin_cache.hpp).
bool entry_is_complete(const fs::path& entry, const std::string& source, const std::string& name) {
  std::error_code error;
  const fs::path plugin = entry / (name + ".so");
  if (!fs::is_regular_file(plugin, error) || !fs::is_regular_file(entry / "entry.json", error)) return false;
  if (read_file(entry / "model.cpp") != source) return false;
  const json record = json::parse(read_file(entry / "entry.json"), nullptr, false);
  if (!record.is_object() || !record.contains("size") || !record.contains("content_hash")) return false;
  const auto size = fs::file_size(plugin, error);
  const auto hash = file_content_hash(plugin);
  return !error && hash && record["size"] == size && record["content_hash"] == content_hash_hex(*hash);
}

// Holds an exclusive flock on a file for its lifetime.
class FileLock {
 public:
  explicit FileLock(const fs::path& path) : descriptor_(::open(path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644)) {
    if (descriptor_ < 0) throw FormulaCompileError("cannot create the lock file " + path.string());
    while (::flock(descriptor_, LOCK_EX) != 0)
      if (errno != EINTR) throw FormulaCompileError("cannot lock " + path.string());
  }
  ~FileLock() { ::close(descriptor_); }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int descriptor_;
};

}  // namespace

Toolchain find_toolchain() {
  const auto data = data_directory();
  const fs::path file = data ? *data / "formula" / "toolchain.json" : fs::path();
  std::error_code error;
  if (!data || !fs::is_regular_file(file, error))
    throw FormulaCompileError("the toolchain file share/nonsep/formula/toolchain.json of this nonsep is missing (" +
                              std::string(data ? "not in " + data->string() : "no share/nonsep found") +
                              "): reinstall nonsep");
  const json description = json::parse(read_file(file), nullptr, false);
  if (!description.is_object() || !description.value("compiler", json()).is_string() ||
      !description.value("flags", json()).is_array() || !description.value("include_directories", json()).is_array())
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
  const auto compiler = locate(toolchain.compiler);
  if (!compiler)
    throw FormulaCompileError(
        "no C++ compiler: " + toolchain.compiler + " " +
        (toolchain.compiler.find('/') != std::string::npos ? "does not exist or cannot run" : "is not in PATH") + "; " +
        install_hint);
  toolchain.compiler = compiler->string();
  auto [status, version] = run_capturing({toolchain.compiler, "--version"});
  if (status != 0)
    throw FormulaCompileError("the compiler " + toolchain.compiler + " does not run (`--version` failed: " + version +
                              "); " + install_hint);
  toolchain.identity = version;
  for (const auto& flag : kernel_flags()) toolchain.flags.push_back(flag);
  return toolchain;
}

std::vector<std::string> kernel_flags() {
  const std::string set = instruction_set_to_use({"x86-64", "x86-64-v3", "x86-64-v4"});
  const int bits = set == "x86-64-v3" ? 1 : set == "x86-64-v4" ? 2 : 0;
  return {"-DNONSEP_SDK_WIDE_KERNEL_SETS=" + std::to_string(bits)};
}

void compile_plugin(const std::string& source, const Toolchain& toolchain, const fs::path& output) {
  const fs::path folder = output.parent_path().empty() ? fs::path(".") : output.parent_path();
  const fs::path work = folder / (".nonsep-compile-" + unique_suffix());
  std::error_code error;
  if (!fs::create_directory(work, error))
    throw FormulaCompileError("cannot create the folder " + work.string() + " to compile in: " + error.message());
  const auto clean = [&] { fs::remove_all(work, error); };
  {
    std::ofstream out(work / "model.cpp", std::ios::binary);
    out << source;
    if (!out) {
      clean();
      throw FormulaCompileError("cannot write " + (work / "model.cpp").string());
    }
  }
  std::vector<std::string> arguments{toolchain.compiler};
  arguments.insert(arguments.end(), toolchain.flags.begin(), toolchain.flags.end());
  for (const auto& include : toolchain.include_directories) arguments.push_back("-I" + include.string());
  arguments.insert(arguments.end(), {"-o", (work / "plugin.so").string(), (work / "model.cpp").string()});
  const auto [status, messages] = run_capturing(arguments);
  if (status != 0) {
    clean();
    throw FormulaCompileError("the compiler " + toolchain.compiler + " failed (exit status " + std::to_string(status) +
                              ") on the formula model's C++:\n" + messages);
  }
  fs::rename(work / "plugin.so", output, error);
  clean();
  if (error) throw FormulaCompileError("cannot write the plugin " + output.string() + ": " + error.message());
}

fs::path cache_directory() {
  if (const char* chosen = std::getenv("NONSEP_CACHE_DIR"); chosen && *chosen) return chosen;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg && fs::path(xdg).is_absolute())
    return fs::path(xdg) / "nonsep";
  if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".cache" / "nonsep";
  return fs::temp_directory_path() / ("nonsep-cache-" + std::to_string(::getuid()));
}

std::string cache_key(const std::string& source, const Toolchain& toolchain) {
  std::uint64_t hash = content_hash(source);
  const auto add = [&](const std::string& part) { hash = content_hash(part + '\0', hash); };
  add(toolchain.compiler);
  add(toolchain.identity);
  for (const auto& flag : toolchain.flags) add(flag);
  for (const auto& include : toolchain.include_directories) add(include.string());
  add(NONSEP_VERSION);
  add(std::to_string(NONSEP_PLUGIN_ABI_VERSION) + "/" + std::to_string(chin_kernel_version));
  return content_hash_hex(hash);
}

CachedPlugin cached_plugin(const FormulaModel& model, const std::function<void(const std::string&)>& say) {
  const Toolchain toolchain = find_toolchain();
  const std::string source = cpp_source(model);
  CachedPlugin result{{}, cache_key(source, toolchain)};
  fs::path root = cache_directory();
  if (!writable_folder(root / "formula")) {
    const fs::path fallback = fs::temp_directory_path() / ("nonsep-cache-" + std::to_string(::getuid()));
    say("the cache folder " + root.string() + " is not writable; using " + fallback.string() +
        " (set NONSEP_CACHE_DIR to choose another)");
    root = fallback;
    if (!writable_folder(root / "formula"))
      throw FormulaCompileError("neither the cache folder nor " + root.string() +
                                " is writable: set NONSEP_CACHE_DIR to a writable folder");
  }
  const fs::path folder = root / "formula";
  const fs::path entry = folder / result.key;
  result.path = entry / (model.name + ".so");
  if (entry_is_complete(entry, source, model.name)) return result;
  FileLock lock(folder / (result.key + ".lock"));
  if (entry_is_complete(entry, source, model.name)) return result;
  std::error_code error;
  if (fs::exists(entry, error)) {
    const fs::path stale = folder / (".stale-" + unique_suffix());
    fs::rename(entry, stale, error);
    fs::remove_all(stale, error);
  }
  say("compiling the formula model '" + model.name + "' into a plugin (first use; cached in " + folder.string() + ")");
  const auto start = std::chrono::steady_clock::now();
  const fs::path building = folder / (".building-" + unique_suffix());
  fs::create_directory(building, error);
  try {
    compile_plugin(source, toolchain, building / (model.name + ".so"));
    const fs::path plugin = building / (model.name + ".so");
    const auto hash = file_content_hash(plugin);
    std::ofstream(building / "model.cpp", std::ios::binary) << source;
    std::ofstream(building / "entry.json") << json{{"key", result.key},
                                                   {"plugin", model.name + ".so"},
                                                   {"size", fs::file_size(plugin)},
                                                   {"content_hash", hash ? content_hash_hex(*hash) : ""},
                                                   {"T", model.T},
                                                   {"V", model.V},
                                                   {"compiler", toolchain.compiler},
                                                   {"nonsep_version", NONSEP_VERSION}}
                                                  .dump(2)
                                           << "\n";
    fs::rename(building, entry);
  } catch (...) {
    fs::remove_all(building, error);
    throw;
  }
  result.compiled = true;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.1f", result.seconds);
  say("compiled in " + std::string(seconds) + " s; later runs reuse it");
  return result;
}

bool attach_formula_plugin(Job& job, std::vector<JobIssue>& issues) {
  try {
    const CachedPlugin plugin =
        cached_plugin(*job.formula, [](const std::string& line) { std::cerr << "nonsep: " << line << std::endl; });
    job.plugin = plugin.path.string();
    job.formula_cache_key = plugin.key;
    return true;
  } catch (const std::exception& error) {
    issues.push_back({"/model/formula", "a formula model that cannot be compiled: " + std::string(error.what()),
                      "a formula model and a working C++ compiler (docs/formula-models.md)"});
    return false;
  }
}

}  // namespace nonsep::host::formula
