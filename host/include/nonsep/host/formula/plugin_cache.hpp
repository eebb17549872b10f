#pragma once
// Formula models compiled into plugins, and the cache that keeps them.
//
// The compiler: share/nonsep/formula/toolchain.json (cmake/NonsepFormula.cmake) names the compiler and flags of the
// build that made this executable, and where the SDK's headers are; NONSEP_CXX names another compiler. Besides the
// baseline kernel, a formula plugin carries the one wider kernel this process would use (instruction_set_to_use):
// each set costs compile time, and a cached plugin serves this machine. The compiler runs through
// compiler_process.hpp: within a time limit, leaving no process behind.
//
// The cache: the folder of cache_folder.hpp (who may write it, and how its files are opened). An entry is
// formula/<key>/ holding <name>.so, model.cpp (the source) and entry.json (the plugin's size and content hash, the
// compiler's identity), where key is the content hash of what determines the plugin: the source, the compiler's
// identity (its resolved path and --version text), the flags, the content of every nonsep header the source
// includes and of the SDK's library (not the folders holding them: a build tree's nonsep and the installed one share
// entries), nonsep's
// version, the plugin ABI and the kernel version. An entry is used only when its files are regular files (checked
// through their descriptors: a FIFO, a device or a link is never read), model.cpp equals the source and the
// plugin's size and hash match entry.json; anything else (a half-written, damaged or planted entry) is removed and
// compiled again. A compile builds in formula/.building-<key>-<unique>/, writes every file with each write
// checked (a full disk is an error naming the file, and nothing is left), and renames the folder to formula/<key>
// whole, under an exclusive lock on formula/<key>.lock, so two runs compiling the same model at once compile it
// once and neither sees a partial entry. A .building-<key>-* folder whose key's lock is free belongs to a nonsep that
// died: the next compile in the cache removes it.
//
// Errors: FormulaCompileError (compiler_process.hpp), with a message naming what to do (no compiler: what to
// install; a compiler error: its output; the time limit; an unsafe cache folder).
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "nonsep/host/formula/cache_folder.hpp"
#include "nonsep/host/formula/compiler_process.hpp"
#include "nonsep/host/formula/formula_model.hpp"
#include "nonsep/host/plugin_loader.hpp"

namespace nonsep::host::formula {

struct Toolchain {
  std::string compiler;  // a path, or a name looked up in PATH
  std::vector<std::string> flags;
  std::vector<std::filesystem::path> include_directories;
  std::vector<std::filesystem::path> libraries;  // linked after the source: the SDK's (plugins/CMakeLists.txt)
  std::string identity;  // the compiler's resolved path and --version text, part of the cache key
  std::string sdk_hash;  // the content hash of the nonsep headers a formula plugin includes and of the libraries, ditto
};

// Where a formula plugin will run: `cache`, on this machine only (the formula cache, whose key holds the flags);
// `share`, anywhere (`nonsep model compile -o`).
enum class PluginUse { cache, share };

// The toolchain of this executable for plugins of that use; throws FormulaCompileError when there is no compiler or
// no SDK headers.
Toolchain find_toolchain(PluginUse use);

// The flags choosing the formula plugin's kernels: the set the host uses here (-DNONSEP_SDK_WIDE_KERNEL_SETS=...),
// beside the baseline, which a cached plugin leaves out when that set is a wider one
// (-DNONSEP_SDK_BASELINE_KERNELS=0: the host would never run it here).
std::vector<std::string> kernel_flags(PluginUse use);

// Compiles `source` into the plugin `output`: in a fresh folder .nonsep-compile-<unique> beside it (removed
// afterwards, and by the compiler's guard when nonsep dies, with the folders `abandon`), then renamed to `output`.
void compile_plugin(const std::string& source, const Toolchain& toolchain, const std::filesystem::path& output,
                    const std::vector<std::filesystem::path>& abandon = {});

std::string cache_key(const std::string& source, const Toolchain& toolchain);

struct CachedPlugin {
  std::filesystem::path path;  // formula/<key>/<name>.so
  std::string key;
  bool compiled = false;  // false: found in the cache
  double seconds = 0.0;   // the compile's wall time
  // The plugin file whose size and hash were checked against entry.json, held open: what load_cached_plugin loads.
  OpenFile file;
};

// The model's plugin from the cache, compiled first when absent. `say` receives progress lines ("compiling ...",
// "compiled in 9.4 s", a fallback note). Throws FormulaCompileError.
CachedPlugin cached_plugin(const FormulaModel& model, const std::function<void(const std::string&)>& say);

// Loads the plugin `cached` checked: through its open descriptor (/proc/self/fd/N), never by its path, which
// leads through the cache's folders again and could by then lead to another file (a cache under a folder that
// others can write: docs/trust-model.md). Its path is the one reported (Plugin::path). Throws PluginError.
Plugin load_cached_plugin(const CachedPlugin& cached);

}  // namespace nonsep::host::formula
