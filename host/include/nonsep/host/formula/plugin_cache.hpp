#pragma once
// Formula models compiled into plugins, and the cache that keeps them.
//
// The compiler: share/nonsep/formula/toolchain.json (cmake/NonsepFormula.cmake) names the compiler and flags of the
// build that made this executable, and where the SDK's headers are; NONSEP_CXX names another compiler. Besides the
// baseline kernel, a formula plugin carries the one wider kernel this process would use (instruction_set_to_use):
// each set costs compile time, and a cached plugin serves this machine.
//
// The cache: NONSEP_CACHE_DIR, else $XDG_CACHE_HOME/nonsep, else $HOME/.cache/nonsep; a folder that cannot be
// created or written falls back to <temporary folder>/nonsep-cache-<uid> (with a note). An entry is
// formula/<key>/ holding <name>.so, model.cpp (the source) and entry.json (the plugin's size and content hash),
// where key is the content hash of the source, the compiler's path and --version text, the flags, the include
// folders, nonsep's version, the plugin ABI and the kernel version. An entry is used only when model.cpp equals the
// source and the plugin's size and hash match entry.json; anything else (a half-written or damaged entry) is
// removed and compiled again. A compile writes into a fresh folder and renames it to formula/<key> whole, under
// an exclusive lock on formula/<key>.lock, so two runs compiling the same model at once compile it once and
// neither sees a partial entry.
//
// Errors: FormulaCompileError, with a message naming what to do (no compiler: what to install; a compiler error:
// its output).
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "nonsep/host/formula/formula_model.hpp"

namespace nonsep::host::formula {

class FormulaCompileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Toolchain {
  std::string compiler;  // a path, or a name looked up in PATH
  std::vector<std::string> flags;
  std::vector<std::filesystem::path> include_directories;
  std::string identity;  // the compiler's --version text, part of the cache key
};

// The toolchain of this executable; throws FormulaCompileError when there is no compiler or no SDK headers.
Toolchain find_toolchain();

// The flags choosing the formula plugin's kernels (-DNONSEP_SDK_WIDE_KERNEL_SETS=...).
std::vector<std::string> kernel_flags();

// Compiles `source` into the plugin `output` (written under a temporary name in the same folder, then renamed).
void compile_plugin(const std::string& source, const Toolchain& toolchain, const std::filesystem::path& output);

// The cache folder: the variables above, not yet checked for being writable.
std::filesystem::path cache_directory();

std::string cache_key(const std::string& source, const Toolchain& toolchain);

struct CachedPlugin {
  std::filesystem::path path;  // formula/<key>/<name>.so
  std::string key;
  bool compiled = false;  // false: found in the cache
  double seconds = 0.0;   // the compile's wall time
};

// The model's plugin from the cache, compiled first when absent. `say` receives progress lines ("compiling ...",
// "compiled in 9.4 s", a fallback note). Throws FormulaCompileError.
CachedPlugin cached_plugin(const FormulaModel& model, const std::function<void(const std::string&)>& say);

// For load_model (job.hpp): the plugin of job.formula from the cache (compiling it first, saying so on standard
// error), into job.plugin and job.formula_cache_key; false with an issue at /model/formula when it cannot be had.
bool attach_formula_plugin(Job& job, std::vector<JobIssue>& issues);

}  // namespace nonsep::host::formula
