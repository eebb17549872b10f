#pragma once
// The processes of one `nonsep run`: MPI ranks when the process was started by mpirun or srun (OpenMPI, MPICH and
// Slurm's PMI put their variables in the environment; see started_by_mpi), one process otherwise. Only the run
// command joins MPI, and only then: `nonsep` without mpirun never loads or initialises the MPI runtime.
//
// Everything here is collective (every rank calls it, in the same order) except rank(), size() and UnitCounter::
// next(). A build without MPI (NONSEP_WITH_MPI=OFF) has the same class with one rank.
#include <cstdint>
#include <memory>
#include <string>

namespace nonsep::host {

// Whether the environment says this process is one of several started by an MPI launcher.
bool started_by_mpi();

class Ranks {
 public:
  // Joins MPI (MPI_Init_thread, funneled: only this thread calls MPI) when started_by_mpi() and the build has MPI;
  // one rank otherwise. Throws std::runtime_error when MPI cannot be initialised.
  static std::unique_ptr<Ranks> join();
  // One rank, no MPI (the tests; a resumed distributed run on one process).
  Ranks() = default;
  ~Ranks();  // MPI_Finalize when joined
  Ranks(const Ranks&) = delete;
  Ranks& operator=(const Ranks&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool joined_mpi() const { return joined_; }

  void barrier() const;
  // The largest of every rank's `value`.
  int max(int value) const;
  std::uint64_t max(std::uint64_t value) const;
  bool any(bool value) const { return max(value ? 1 : 0) != 0; }
  // The lowest rank that failed and its message, on every rank; rank -1 and "" when none did.
  struct Failure {
    int rank = -1;
    std::string message;
  };
  Failure first_failure(bool failed, const std::string& message) const;
  // Rank 0's text, on every rank.
  std::string broadcast(const std::string& text) const;

  // Hands out 0, 1, 2, ... to whichever rank asks first (MPI one-sided fetch-and-add on a counter held by rank 0;
  // a plain counter on one rank): the dynamic distribution of work units. Creating and destroying it is collective.
  class UnitCounter {
   public:
    explicit UnitCounter(const Ranks& ranks);
    ~UnitCounter();
    UnitCounter(const UnitCounter&) = delete;
    UnitCounter& operator=(const UnitCounter&) = delete;
    std::uint64_t next();

   private:
    struct Window;
    std::unique_ptr<Window> window_;
    std::uint64_t local_ = 0;
  };

 private:
  int rank_ = 0, size_ = 1;
  bool joined_ = false;
};

}  // namespace nonsep::host
