#pragma once
// The output folder of one run or study, held for the time of the run.
//
// Ownership. A folder belongs to at most one run at a time: RunFolder takes an exclusive lock (flock on
// `.nonsep.lock`, which holds the owner's pid); a second run into the same folder is refused with that pid. The lock
// goes with the process, however it ends. `.nonsep-run.json` records what the folder holds: the kind ("run",
// "study" or "unit") and the job file (its absolute path) that wrote it; in a folder written before it existed,
// summary.json's "job" tells.
//
// Earlier results. A new run refuses a folder that holds
//   - a checkpoint (checkpoint.json): an interrupted run, which `--resume` continues and `--force` discards;
//   - results of another job or kind, or nonsep results of unknown origin: unless `--force`.
//   - the work units of an interrupted distributed run (`units/`, cluster/distributed_run.hpp): likewise.
// A work unit of a distributed run (kind "unit") is refused to any run but its own, `--force` included.
// Results of the same job (the same job file, the same kind) are the run's to replace. Starting (fresh or forced),
// the run removes every file an earlier run left (the names in `output_files`), so a failed or killed run never
// leaves the earlier run's summary beside its own partial files. Temporary files of dead runs (".*.tmp-*") are
// removed too. Resuming keeps everything.
//
// Before anything is computed (fresh, forced or resumed) the folder is checked to take files and renames, and every
// output name to be free or a regular file (not a folder, link or device in the way), so that a run that could not
// save its results fails at once (exit 2), not after its steps.
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/held_folder.hpp"

namespace nonsep::host {

// The folder of a distributed run's work units (cluster/distributed_run.hpp), removed by a fresh or forced start.
inline constexpr const char* units_folder = "units";

// What the folder is opened for.
enum class FolderUse {
  fresh,   // a new run; refuses earlier results of another job or kind, and any checkpoint
  resume,  // continue from the checkpoint (which must exist: checked by load_checkpoint)
  force,   // a new run that first removes every file of whatever ran there
};

// The folder cannot be used: locked by another run, or holding results this run may not replace. The message
// names the folder, what is there and what to do. Invalid input (exit 2).
class FolderInUse : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class RunFolder {
 public:
  // Creates the folder if missing, locks it and checks it as described above. `kind`: "run", "study" or "unit" (a
  // distributed run's work unit); `job_file`:
  // the job as given on the command line. Throws FolderInUse, or OutputError when it cannot be created, locked or
  // written.
  RunFolder(const std::filesystem::path& directory, const std::string& kind, const std::filesystem::path& job_file,
            FolderUse use);
  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;
  ~RunFolder();  // releases the lock

  const std::filesystem::path& path() const { return directory_; }

  // The names of every file a run or study may write into its folder.
  static const std::vector<std::string>& output_files();

 private:
  std::filesystem::path directory_;
  std::unique_ptr<HeldFolder> held_;  // every file of the run resolves through it (held_folder.hpp)
  int lock_ = -1;
};

}  // namespace nonsep::host
