// Compiling formula models and caching their plugins (plugin_cache.hpp).
#include "nonsep/host/formula/plugin_cache.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "nonsep/core/kernel/chin_kernel.hpp"
#include "nonsep/host/formula/cpp_source.hpp"
#include "nonsep/host/output/content_hash.hpp"
#include "nonsep/plugin_abi.h"

#ifndef NONSEP_VERSION
#error "NONSEP_VERSION must be defined by the build"
#endif

namespace nonsep::host::formula {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr std::size_t max_entry_json_bytes = std::size_t{1} << 20;

std::string unique_suffix() {
  static std::uint64_t counter = 0;
  return std::to_string(::getpid()) + "-" +
         std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + "-" + std::to_string(++counter);
}

// The plugin of formula/<key>/, held open, when that is a complete entry for `source` (plugin_cache.hpp), its files
// read through descriptors; nothing otherwise.
std::optional<OpenFile> complete_entry_plugin(const CacheFolder& cache, const std::string& key,
                                              const std::string& source, const std::string& name) {
  const int entry = cache.open_folder(key);
  if (entry < 0) return std::nullopt;
  const auto text = read_entry_file(entry, "model.cpp", source.size());
  const auto record_text = read_entry_file(entry, "entry.json", max_entry_json_bytes);
  auto plugin = open_entry_file(entry, name + ".so");
  ::close(entry);
  if (!text || *text != source || !record_text || !plugin) return std::nullopt;
  const json record = json::parse(*record_text, nullptr, false);
  if (!record.is_object() || record.value("size", json()) != plugin->size ||
      record.value("content_hash", json()) != content_hash_hex(plugin->hash))
    return std::nullopt;
  return std::move(plugin->file);
}

// Removes the build folders of nonsep processes that died compiling (.building-<key>-* whose key's lock is free)
// and what one that died removing an entry left (.stale-*, never used again).
void remove_abandoned_builds(const CacheFolder& cache) {
  const std::string prefix = ".building-";
  std::error_code error;
  std::vector<std::string> names;
  for (fs::directory_iterator it(cache.path(), error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) == 0) names.push_back(name);
    std::error_code ignored;
    if (name.rfind(".stale-", 0) == 0) fs::remove_all(it->path(), ignored);
  }
  for (const auto& name : names) {
    const std::size_t dash = name.find('-', prefix.size());
    if (dash == std::string::npos) continue;
    const CacheLock lock(cache, name.substr(prefix.size(), dash - prefix.size()) + ".lock", false);
    if (lock.held()) cache.remove(name);
  }
}

// Writes the entry's files into the folder `building` and renames it to `key`; throws FormulaCompileError (the
// folder is then removed by the caller).
void complete_entry(const CacheFolder& cache, const std::string& building, const std::string& key,
                    const FormulaModel& model, const std::string& source, const Toolchain& toolchain) {
  const int folder = cache.open_folder(building);
  if (folder < 0) throw FormulaCompileError("the folder " + (cache.path() / building).string() + " went missing");
  try {
    const auto plugin = entry_file_size_and_hash(folder, model.name + ".so");
    if (!plugin) throw FormulaCompileError("the compiler wrote no plugin file " + model.name + ".so");
    write_entry_file(folder, "model.cpp", source, cache.path() / building / "model.cpp");
    write_entry_file(folder, "entry.json",
                     json{{"key", key},
                          {"plugin", model.name + ".so"},
                          {"size", plugin->first},
                          {"content_hash", content_hash_hex(plugin->second)},
                          {"H", model.h_tree ? json(model.H) : json(nullptr)},
                          {"T", model.h_tree ? json(nullptr) : json(model.T)},
                          {"V", model.h_tree ? json(nullptr) : json(model.V)},
                          {"compiler", toolchain.compiler},
                          {"compiler_identity", toolchain.identity},
                          {"nonsep_version", NONSEP_VERSION}}
                             .dump(2) +
                         "\n",
                     cache.path() / building / "entry.json");
  } catch (...) {
    ::close(folder);
    throw;
  }
  ::close(folder);
  if (!cache.rename(building, key))
    throw FormulaCompileError("cannot rename " + (cache.path() / building).string() + " to " +
                              (cache.path() / key).string());
}

}  // namespace

void compile_plugin(const std::string& source, const Toolchain& toolchain, const fs::path& output,
                    const std::vector<fs::path>& abandon) {
  const fs::path folder = output.parent_path().empty() ? fs::path(".") : output.parent_path();
  const fs::path work = folder / (".nonsep-compile-" + unique_suffix());
  std::error_code error;
  if (!fs::create_directory(work, error))
    throw FormulaCompileError("cannot create the folder " + work.string() + " to compile in: " + error.message());
  const auto clean = [&] { fs::remove_all(work, error); };
  std::vector<std::string> arguments{toolchain.compiler};
  arguments.insert(arguments.end(), toolchain.flags.begin(), toolchain.flags.end());
  for (const auto& include : toolchain.include_directories) arguments.push_back("-I" + include.string());
  arguments.insert(arguments.end(), {"-o", (work / "plugin.so").string(), (work / "model.cpp").string()});
  for (const auto& library : toolchain.libraries) arguments.push_back(library.string());
  std::vector<fs::path> remove_when_abandoned = abandon;
  remove_when_abandoned.push_back(work);
  CompilerOutcome outcome;
  try {
    const int descriptor = ::open(work.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (descriptor < 0) throw FormulaCompileError("cannot open the folder " + work.string());
    try {
      write_entry_file(descriptor, "model.cpp", source, work / "model.cpp");
    } catch (...) {
      ::close(descriptor);
      throw;
    }
    ::close(descriptor);
    outcome = run_compiler(arguments, compile_time_limit(), remove_when_abandoned);
  } catch (...) {
    clean();
    throw;
  }
  if (outcome.status != 0) {
    clean();
    throw FormulaCompileError("the compiler " + toolchain.compiler + " failed (exit status " +
                              std::to_string(outcome.status) + ") on the formula model's C++:\n" + outcome.output);
  }
  fs::rename(work / "plugin.so", output, error);
  clean();
  if (error) throw FormulaCompileError("cannot write the plugin " + output.string() + ": " + error.message());
}

std::string cache_key(const std::string& source, const Toolchain& toolchain) {
  std::uint64_t hash = content_hash(source);
  const auto add = [&](const std::string& part) { hash = content_hash(part + '\0', hash); };
  add(toolchain.identity);
  for (const auto& flag : toolchain.flags) add(flag);
  add(toolchain.sdk_hash);
  add(NONSEP_VERSION);
  add(std::to_string(NONSEP_PLUGIN_ABI_VERSION) + "/" + std::to_string(chin_kernel_version));
  return content_hash_hex(hash);
}

CachedPlugin cached_plugin(const FormulaModel& model, const std::function<void(const std::string&)>& say) {
  const Toolchain toolchain = find_toolchain(PluginUse::cache);
  const std::string source = cpp_source(model);
  CachedPlugin result;
  result.key = cache_key(source, toolchain);
  const CacheFolder cache = CacheFolder::open(say);
  result.path = cache.path() / result.key / (model.name + ".so");
  if (auto plugin = complete_entry_plugin(cache, result.key, source, model.name)) {
    result.file = std::move(*plugin);
    return result;
  }
  const CacheLock lock(cache, result.key + ".lock");
  if (auto plugin = complete_entry_plugin(cache, result.key, source, model.name)) {
    result.file = std::move(*plugin);
    return result;
  }
  remove_abandoned_builds(cache);
  cache.remove(result.key);
  say("compiling the formula model '" + model.name + "' into a plugin (first use; cached in " + cache.path().string() +
      ")");
  const auto start = std::chrono::steady_clock::now();
  const std::string building = ".building-" + result.key + "-" + unique_suffix();
  cache.make_folder(building);
  try {
    compile_plugin(source, toolchain, cache.path() / building / (model.name + ".so"), {cache.path() / building});
    complete_entry(cache, building, result.key, model, source, toolchain);
  } catch (...) {
    cache.remove(building);
    throw;
  }
  auto plugin = complete_entry_plugin(cache, result.key, source, model.name);
  if (!plugin)
    throw FormulaCompileError("the cache entry " + (cache.path() / result.key).string() +
                              " changed while it was being made; run again");
  result.file = std::move(*plugin);
  result.compiled = true;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.1f", result.seconds);
  say("compiled in " + std::string(seconds) + " s; later runs reuse it");
  return result;
}

Plugin load_cached_plugin(const CachedPlugin& cached) {
  return load_plugin_file(cached.file.reopen_path(), cached.path);
}

}  // namespace nonsep::host::formula
