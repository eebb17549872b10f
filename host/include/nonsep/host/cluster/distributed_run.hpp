#pragma once
// One ensemble run spread over MPI ranks (ranks.hpp): `mpirun -n N nonsep run JOB.json [--threads T]`.
//
// Work units. The ensemble is cut into units of consecutive trajectories, their size a multiple of the driver's
// block (run_block_size) chosen from the number of trajectories alone (unit_size), so the cut does not depend on
// the number of ranks. Each unit is an ordinary run (run_job) of the job restricted to its trajectories, in its own
// folder OUTPUT/units/NNNNNN/ with its own files, checkpoints and threads. Ranks take units from a shared counter
// (Ranks::UnitCounter): a rank that finishes early takes the next unit, so the load balances itself whatever the
// trajectories cost. No rank waits for another while stepping: the ranks meet only at the start and the end.
//
// The end. When every unit is done, rank 0 merges the units' files into OUTPUT (merge_outputs.hpp): trajectory.csv,
// poincare.csv, lyapunov.csv, trajectories.csv and summary.json are byte for byte those of one process with one
// thread (summary.json's wall_seconds aside), and removes units/.
//
// Interrupts. SIGINT or SIGTERM delivered to the ranks (Slurm's scancel does), or SIGUSR1 (which mpirun passes on
// to every rank; OpenMPI 4.1's mpirun does not pass SIGTERM or SIGINT on): each rank's current unit saves its
// checkpoint and stops, no rank takes another unit, rank 0 writes summary.json with status "interrupted" and what
// is done, and every rank exits with 130 (SIGINT) or 143. units/ (plan.json, the finished units, the checkpoints of the
// others) is the checkpoint: `nonsep run JOB.json --resume` continues it with any number of ranks, one process
// included, and ends bit for bit as an uninterrupted run.
//
// Verification. A finished unit is sealed by the rank that ran it (unit_seal.hpp); only sealed units count as done.
// Rank 0 verifies every sealed unit when a resume starts and every unit before the merge, and refuses (exit 2,
// naming the unit) one that does not match its seal or this job; units/ and the unit folders must be folders, not
// links. A unit's folder has the kind "unit" (run_folder.hpp), which no other run may take over.
//
// Failures. A unit that cannot start or write its files stops its rank's work; every rank then ends with exit
// status 2 and rank 0 prints the message of the lowest failing rank (RankFailure). A plugin that fails on some
// states retires them as in any run; it is not a failure of the run.
#include <cstddef>
#include <filesystem>
#include <stdexcept>

#include "nonsep/host/cluster/ranks.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/launch/run_job.hpp"

namespace nonsep::host {

// A failure of the distributed run as a whole, known to every rank; what() is the message to print (rank 0 prints it).
class RankFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Trajectories per work unit for an ensemble of `trajectories`: about 64 units, each a whole number of blocks.
std::size_t unit_size(std::size_t trajectories);

// Whether `directory` holds the work units of a distributed run (units/plan.json).
bool has_units(const std::filesystem::path& directory);

// Runs `loaded` (a single run, not a study) on every rank of `ranks`; collective. The outcome is complete on rank 0;
// elsewhere only its exit_status is set (the same on every rank). Throws RankFailure on every rank when the run
// cannot start or a unit cannot be run.
RunOutcome run_distributed(const LoadedJob& loaded, const RunOptions& options, const Ranks& ranks);

}  // namespace nonsep::host
