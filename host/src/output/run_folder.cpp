#include "nonsep/host/output/run_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <csignal>
#include <cstring>
#include <exception>
#include <nlohmann/json.hpp>
#include <optional>

namespace nonsep::host {

namespace {

constexpr const char* lock_name = ".nonsep.lock";
constexpr const char* manifest_name = ".nonsep-run.json";

// At most the first `limit` bytes of a file, "" when there is none. Never blocks (a FIFO there) nor follows a link:
// throws OutputError for anything but a regular file (read_regular_file).
std::string read_head(const std::filesystem::path& path, std::size_t limit) {
  return read_regular_file(path, limit).value_or("");
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

// No output name is a FIFO, a device or a socket: opening one could block the run (while it holds the lock) or write
// where no file is kept. Whatever the use of the folder, --force included: nonsep does not remove such things.
void check_no_special_files(const std::filesystem::path& directory) {
  for (const auto& name : RunFolder::output_files()) {
    struct stat status {};
    if (::lstat((directory / name).c_str(), &status) != 0) continue;
    if (S_ISREG(status.st_mode) || S_ISDIR(status.st_mode) || S_ISLNK(status.st_mode)) continue;
    throw OutputError("cannot write " + (directory / name).string() + ": it is " + file_kind(status.st_mode) +
                      ", in the way of the run's file of that name; remove it, or give this run another folder "
                      "(--output)");
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
                             : std::filesystem::is_fifo(status)    ? "a FIFO (named pipe)"
                                                                   : "not a regular file";
    throw OutputError("cannot write " + (directory / name).string() + ": " + what +
                      " is in the way of the run's file of that name; move it, or give this run another folder "
                      "(--output)");
  }
}

// Who holds the lock: the pid the lock file names, when that process is alive. A pid written by an earlier run that
// has ended (the lock goes with the process, the file stays) does not name the holder: another process locked the
// file without writing its pid.
std::string lock_holder(const std::filesystem::path& lock_path) {
  std::string holder;
  try {
    holder = read_head(lock_path, 64);
  } catch (const OutputError&) {
  }
  while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
  int pid = 0;
  const auto [end, failed] = std::from_chars(holder.data(), holder.data() + holder.size(), pid);
  const bool alive = failed == std::errc() && end == holder.data() + holder.size() && pid > 0 &&
                     (::kill(pid, 0) == 0 || errno == EPERM);
  if (alive) return "another nonsep run (pid " + holder + ")";
  return "another process, which holds the lock on " + lock_path.string() +
         (holder.empty() ? std::string() : " (the pid " + holder + " written there is of an earlier run, ended)");
}

}  // namespace

const std::vector<std::string>& RunFolder::output_files() {
  static const std::vector<std::string> names{
      "summary.json",    "trajectory.csv",  "trajectories.csv", "poincare.csv",       "lyapunov.csv",
      "checkpoint.json", "convergence.csv", "results.h5",       "work_precision.csv", manifest_name};
  return names;
}

RunFolder::RunFolder(const std::filesystem::path& directory, const std::string& kind,
                     const std::filesystem::path& job_file, FolderUse use)
    : directory_(directory) {
  std::error_code error;
  if (std::filesystem::is_symlink(std::filesystem::symlink_status(directory, error)) &&
      !std::filesystem::exists(directory, error))
    throw OutputError("cannot use the output folder " + directory.string() + ": it is a symbolic link to " +
                      std::filesystem::read_symlink(directory, error).string() +
                      ", which does not exist; create that folder, or give this run another one (--output)");
  held_ = std::make_unique<HeldFolder>(directory);
  const auto lock_path = directory / lock_name;
  lock_ = ::openat(held_->descriptor(), lock_name, O_RDWR | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
  if (lock_ < 0)
    throw OutputError("cannot create " + lock_path.string() + " in the output folder: " + std::strerror(errno));
  if (struct stat status{}; ::fstat(lock_, &status) != 0 || !S_ISREG(status.st_mode)) {
    ::close(lock_);
    lock_ = -1;
    throw OutputError("cannot lock the output folder " + directory.string() + ": " + lock_path.string() +
                      " is not a regular file; remove it");
  }
  if (::flock(lock_, LOCK_EX | LOCK_NB) != 0) {
    const int reason = errno;
    ::close(lock_);
    lock_ = -1;
    if (reason != EWOULDBLOCK) throw OutputError("cannot lock " + lock_path.string() + ": " + std::strerror(reason));
    throw FolderInUse("the output folder " + directory.string() + " is in use by " + lock_holder(lock_path) +
                      "; wait for it to end, or give this run another folder (--output)");
  }
  // Refused after this point, the folder is let go at once (the lock would otherwise stay with this process).
  struct UnlockOnThrow {
    int& lock;
    int exceptions = std::uncaught_exceptions();
    ~UnlockOnThrow() {
      if (std::uncaught_exceptions() > exceptions) {
        ::close(lock);
        lock = -1;
      }
    }
  } unlock_on_throw{lock_};
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(lock_, 0) != 0 || ::pwrite(lock_, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size()))
    throw OutputError("cannot write " + lock_path.string() + ": " + std::strerror(errno));

  check_no_special_files(directory);
  if (const auto manifest = read_manifest(directory); manifest && manifest->kind == "unit" && kind != "unit")
    throw FolderInUse("the output folder " + directory.string() +
                      " is a work unit of a distributed run (cluster/distributed_run.hpp), which belongs to that "
                      "run, --force or not: resume the distributed run in the folder above its units/, or give this "
                      "run another folder (--output)");
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
  for (const auto& name : output_files()) remove_file(directory / name);
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
