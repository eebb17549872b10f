#include "nonsep/host/platform/installation.hpp"

#include <algorithm>

#ifndef NONSEP_DATA_DIR_FROM_EXECUTABLE
#error "NONSEP_DATA_DIR_FROM_EXECUTABLE (share/nonsep relative to the installed bin/) must be defined by the build"
#endif
#ifndef NONSEP_BUILD_DATA_DIR_FROM_EXECUTABLE
#error "NONSEP_BUILD_DATA_DIR_FROM_EXECUTABLE (share/nonsep relative to the build tree's bin/) must be defined"
#endif

namespace nonsep::host {

namespace fs = std::filesystem;

std::vector<fs::path> data_directory_candidates() {
  std::vector<fs::path> candidates;
  std::error_code error;
  // Linux: the executable's own file, whatever the current folder or argv[0] (the loader uses the same).
  const fs::path executable = fs::read_symlink("/proc/self/exe", error);
  if (error) return candidates;
  for (const char* relative : {NONSEP_DATA_DIR_FROM_EXECUTABLE, NONSEP_BUILD_DATA_DIR_FROM_EXECUTABLE}) {
    const fs::path folder = (executable.parent_path() / relative).lexically_normal();
    if (std::find(candidates.begin(), candidates.end(), folder) == candidates.end()) candidates.push_back(folder);
  }
  return candidates;
}

std::optional<fs::path> data_directory() {
  for (const fs::path& folder : data_directory_candidates()) {
    std::error_code error;
    if (fs::is_regular_file(folder / "README.md", error)) return folder;
  }
  return std::nullopt;
}

std::string manual_location() {
  if (const auto folder = data_directory()) {
    std::error_code error;
    const fs::path readme = fs::canonical(*folder / "README.md", error);
    return (error ? *folder / "README.md" : readme).string();
  }
  std::string looked;
  for (const fs::path& folder : data_directory_candidates()) looked += (looked.empty() ? "" : ", ") + folder.string();
  return "README.md of the nonsep sources (not found beside this executable: looked in " +
         (looked.empty() ? std::string("no folder, the executable's location is unknown") : looked) + ")";
}

}  // namespace nonsep::host
