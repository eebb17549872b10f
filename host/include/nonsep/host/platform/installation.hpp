#pragma once
// Where the running executable's own files are: the manual (README.md), the docs, the job schema and the example
// job files, in share/nonsep/ found relative to the executable (installed: <prefix>/bin/../share/nonsep; build
// tree: build/bin/../share/nonsep, whose entries are links to the sources; see cmake/NonsepShare.cmake). No path
// of the building machine is compiled in, so an installed tree can be moved.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace nonsep::host {

// The folders tried for share/nonsep, in order (each absolute, relative to the running executable's folder).
std::vector<std::filesystem::path> data_directory_candidates();

// The first candidate that holds README.md, or nothing.
std::optional<std::filesystem::path> data_directory();

// Where to read the manual, for --help and messages: the README.md found in data_directory() with symbolic links
// resolved (so a build tree names the source README.md), or "README.md of the nonsep sources (not found beside
// this executable: looked in ...)".
std::string manual_location();

}  // namespace nonsep::host
