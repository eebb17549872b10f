#include "nonsep/host/output/run_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

namespace nonsep::host {

namespace {

constexpr const char* lock_name = ".nonsep.lock";
constexpr const char* manifest_name = ".nonsep-run.json";

// At most the first `limit` bytes of a file ("" when it cannot be read), read in pieces: a limit meant for a large
// summary.json is not allocated (and cleared) for a small one.
std::string read_head(const std::filesystem::path& path, std::size_t limit) {
  std::ifstream in(path, std::ios::binary);
  std::string text;
  char buffer[1 << 14];
  while (in && text.size() < limit) {
    in.read(buffer, static_cast<std::streamsize>(std::min(sizeof buffer, limit - text.size())));
    text.append(buffer, static_cast<std::size_t>(in.gcount()));
  }
  return text;
}

bool is_temporary(const std::string& name) {
  return name.size() > 1 && name[0] == '.' && name.find(".tmp-") != std::string::npos;
}

struct Manifest {
  std::string kind, job;
};

// What the folder says it holds: its manifest, or, in a folder written before manifests existed, the job named by
// its summary.json (resolved as it was given, against the current folder). Nothing when neither tells.
std::optional<Manifest> read_manifest(const std::filesystem::path& directory) {
  std::error_code error;
  const auto path = directory / manifest_name;
  if (!std::filesystem::exists(std::filesystem::symlink_status(path, error))) {
    try {
      const auto summary = nlohmann::json::parse(read_head(directory / "summary.json", 1 << 24));
      const std::string job = summary.at("job").get<std::string>();
      return Manifest{summary.contains("study") ? "study" : "run",
                      std::filesystem::weakly_canonical(std::filesystem::absolute(job)).string()};
    } catch (const std::exception&) {
      return std::nullopt;
    }
  }
  try {
    const auto document = nlohmann::json::parse(read_head(path, 1 << 16));
    return Manifest{document.at("kind").get<std::string>(), document.at("job").get<std::string>()};
  } catch (const nlohmann::json::exception&) {
    return Manifest{"unknown", "an unreadable " + std::string(manifest_name)};
  }
}

// Every output name is free or a regular file: a folder, a link or a device where the run must write a file would
// make it fail at its end (the rename of summary.json), after all the computing.
void check_outputs_placeable(const std::filesystem::path& directory) {
  for (const auto& name : RunFolder::output_files()) {
    std::error_code error;
    const auto status = std::filesystem::symlink_status(directory / name, error);
    if (!std::filesystem::exists(status) || std::filesystem::is_regular_file(status)) continue;
    const std::string what = std::filesystem::is_directory(status) ? "a folder"
                             : std::filesystem::is_symlink(status) ? "a symbolic link"
                                                                   : "not a regular file";
    throw OutputError("cannot write " + (directory / name).string() + ": " + what +
                      " is in the way of the run's file of that name; move it, or give this run another folder "
                      "(--output)");
  }
}

}  // namespace

const std::vector<std::string>& RunFolder::output_files() {
  static const std::vector<std::string> names{"summary.json",    "trajectory.csv", "trajectories.csv",
                                              "poincare.csv",    "lyapunov.csv",   "checkpoint.json",
                                              "convergence.csv", "results.h5",     manifest_name};
  return names;
}

RunFolder::RunFolder(const std::filesystem::path& directory, const std::string& kind,
                     const std::filesystem::path& job_file, FolderUse use)
    : directory_(directory) {
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw OutputError("cannot create the output folder " + directory.string() + ": " + error.message());
  const auto lock_path = directory / lock_name;
  lock_ = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (lock_ < 0)
    throw OutputError("cannot create " + lock_path.string() + " in the output folder: " + std::strerror(errno));
  if (::flock(lock_, LOCK_EX | LOCK_NB) != 0) {
    const int reason = errno;
    ::close(lock_);
    lock_ = -1;
    if (reason != EWOULDBLOCK) throw OutputError("cannot lock " + lock_path.string() + ": " + std::strerror(reason));
    std::string holder = read_head(lock_path, 64);
    while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
    throw FolderInUse("the output folder " + directory.string() + " is in use by another nonsep run (pid " +
                      (holder.empty() ? std::string("unknown") : holder) +
                      "); wait for it to end, or give this run another folder (--output)");
  }
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(lock_, 0) != 0 || ::pwrite(lock_, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size()))
    throw OutputError("cannot write " + lock_path.string() + ": " + std::strerror(errno));

  // We hold the lock: any temporary file here belongs to a run that died before renaming it.
  for (const auto& entry : std::filesystem::directory_iterator(directory, error))
    if (is_temporary(entry.path().filename().string())) std::filesystem::remove(entry.path(), error);

  if (use == FolderUse::resume) {
    check_outputs_placeable(directory);
    // Proves, before anything is computed, that the folder still takes files and renames.
    const auto manifest = read_head(directory / manifest_name, 1 << 16);
    if (!manifest.empty()) write_file_atomically(directory / manifest_name, manifest);
    return;
  }
  const std::string job = std::filesystem::weakly_canonical(std::filesystem::absolute(job_file)).string();
  if (use == FolderUse::fresh) {
    if (std::filesystem::exists(std::filesystem::symlink_status(directory / "checkpoint.json")))
      throw FolderInUse("the output folder " + directory.string() +
                        " holds the checkpoint of an interrupted run (checkpoint.json): `--resume` continues it, "
                        "`--force` discards it and starts over");
    if (std::filesystem::exists(std::filesystem::symlink_status(directory / units_folder)))
      throw FolderInUse("the output folder " + directory.string() +
                        " holds the work units of an interrupted distributed run (" + units_folder +
                        "/): `--resume` continues it, with any number of MPI ranks; `--force` discards it and "
                        "starts over");
    bool results = false;
    for (const auto& name : output_files())
      results |= std::filesystem::exists(std::filesystem::symlink_status(directory / name));
    const auto manifest = read_manifest(directory);
    if (results && !manifest)
      throw FolderInUse("the output folder " + directory.string() + " holds results of unknown origin (no " +
                        manifest_name +
                        " nor a summary.json naming their job); `--force` removes them, or give this run another "
                        "folder (--output)");
    if (manifest && (manifest->kind != kind || manifest->job != job))
      throw FolderInUse("the output folder " + directory.string() + " holds the results of another " +
                        (manifest->kind == kind ? kind : manifest->kind) + " (" + manifest->job +
                        "); `--force` replaces them, or give this run another folder (--output)");
  }
  for (const auto& name : output_files()) std::filesystem::remove(directory / name, error);
  std::filesystem::remove_all(directory / units_folder, error);
  if (error) throw OutputError("cannot remove " + (directory / units_folder).string() + ": " + error.message());
  check_outputs_placeable(directory);
  // Also proves, before anything is computed, that the folder takes files and renames.
  write_file_atomically(directory / manifest_name, nlohmann::json{{"kind", kind}, {"job", job}}.dump(2) + "\n");
}

RunFolder::~RunFolder() {
  if (lock_ >= 0) ::close(lock_);
}

}  // namespace nonsep::host
