#pragma once
// Output folders held open by a descriptor for the time of a run, and files resolved relative to them.
//
// RunFolder (run_folder.hpp) opens its folder once, locks it and holds it as a HeldFolder. Every file whose path
// lies inside a held folder is then opened, created, renamed and removed relative to the folder's descriptor
// (openat, renameat, unlinkat), never by its name from the top again: a folder that is renamed, or replaced by a
// symbolic link to somewhere else while the run goes on, does not redirect the run's files; they go on going to the
// folder that was opened and locked. Sub-folders of a held folder (a distributed run's units/NNNNNN) are opened from
// its descriptor one name at a time without following links. Paths outside every held folder resolve as usual.
//
// Held folders are registered by their path as given (lexically normalised), process-wide; a path matches when the
// folder is one of its leading components. Thread-safe.
#include <filesystem>
#include <string>

namespace nonsep::host {

class HeldFolder {
 public:
  // Creates the folder at `path` if missing, opens it and holds it. Inside another held folder it is created and
  // opened from that folder's descriptor without following links. Throws OutputError.
  explicit HeldFolder(const std::filesystem::path& path);
  HeldFolder(const HeldFolder&) = delete;
  HeldFolder& operator=(const HeldFolder&) = delete;
  ~HeldFolder();

  int descriptor() const { return descriptor_; }

 private:
  std::string key_;
  int descriptor_ = -1;
};

// Where the file at `path` is: the descriptor of its folder and its name there. The descriptor is a held folder's,
// one opened beneath it (owned: closed with the FileLocation), or AT_FDCWD with the path itself for a path outside
// every held folder. Throws OutputError when a folder between the held one and the file is missing or is a link.
class FileLocation {
 public:
  explicit FileLocation(const std::filesystem::path& path);
  FileLocation(const FileLocation&) = delete;
  FileLocation& operator=(const FileLocation&) = delete;
  ~FileLocation();

  int folder() const { return folder_; }
  const char* name() const { return name_.c_str(); }

 private:
  int folder_;
  bool owned_ = false;
  std::string name_;
};

// A path to give libraries that open files by name (HDF5, streams): "/proc/self/fd/N/REST" for a path inside a held
// folder, which the kernel resolves through the held descriptor; `path` itself otherwise.
std::filesystem::path held_path(const std::filesystem::path& path);

}  // namespace nonsep::host
