#include "nonsep/host/cluster/ranks.hpp"

#include <cstdlib>
#include <stdexcept>
#include <vector>

#ifdef NONSEP_HAVE_MPI
#include <mpi.h>
#endif

namespace nonsep::host {

bool started_by_mpi() {
  // OpenMPI's mpirun, MPICH/Hydra and Slurm's srun (PMI-1/2, PMIx) each set one of these in every rank.
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "PMI_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}

#ifdef NONSEP_HAVE_MPI

namespace {
void check(int code, const char* what) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw std::runtime_error(std::string("MPI: ") + what +
                           " failed: " + std::string(text, static_cast<std::size_t>(length)));
}
}  // namespace

std::unique_ptr<Ranks> Ranks::join() {
  auto ranks = std::make_unique<Ranks>();
  if (!started_by_mpi()) return ranks;
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) {
    int provided = 0;
    check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  }
  // Errors come back as codes (turned into exceptions by check) instead of aborting every rank at once.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &ranks->rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks->size_);
  ranks->joined_ = true;
  return ranks;
}

Ranks::~Ranks() {
  if (!joined_) return;
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}

void Ranks::barrier() const {
  if (joined_) check(MPI_Barrier(MPI_COMM_WORLD), "MPI_Barrier");
}

int Ranks::max(int value) const {
  int result = value;
  if (joined_) check(MPI_Allreduce(&value, &result, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD), "MPI_Allreduce");
  return result;
}

std::uint64_t Ranks::max(std::uint64_t value) const {
  std::uint64_t result = value;
  if (joined_) check(MPI_Allreduce(&value, &result, 1, MPI_UINT64_T, MPI_MAX, MPI_COMM_WORLD), "MPI_Allreduce");
  return result;
}

Ranks::Failure Ranks::first_failure(bool failed, const std::string& message) const {
  if (!joined_) return failed ? Failure{0, message} : Failure{};
  const int mine = failed ? rank_ : size_;
  int first = size_;
  check(MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD), "MPI_Allreduce");
  if (first == size_) return {};
  std::uint64_t length = first == rank_ ? message.size() : 0;
  check(MPI_Bcast(&length, 1, MPI_UINT64_T, first, MPI_COMM_WORLD), "MPI_Bcast");
  std::string text = first == rank_ ? message : std::string(length, '\0');
  check(MPI_Bcast(text.data(), static_cast<int>(length), MPI_CHAR, first, MPI_COMM_WORLD), "MPI_Bcast");
  return {first, text};
}

std::string Ranks::broadcast(const std::string& text) const {
  if (!joined_) return text;
  std::uint64_t length = text.size();
  check(MPI_Bcast(&length, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD), "MPI_Bcast");
  std::string result = rank_ == 0 ? text : std::string(length, '\0');
  check(MPI_Bcast(result.data(), static_cast<int>(length), MPI_CHAR, 0, MPI_COMM_WORLD), "MPI_Bcast");
  return result;
}

struct Ranks::UnitCounter::Window {
  MPI_Win window = MPI_WIN_NULL;
  std::uint64_t* counter = nullptr;
};

Ranks::UnitCounter::UnitCounter(const Ranks& ranks) {
  if (!ranks.joined_mpi()) return;
  window_ = std::make_unique<Window>();
  const MPI_Aint bytes = ranks.rank() == 0 ? static_cast<MPI_Aint>(sizeof(std::uint64_t)) : 0;
  check(MPI_Win_allocate(bytes, sizeof(std::uint64_t), MPI_INFO_NULL, MPI_COMM_WORLD, &window_->counter,
                         &window_->window),
        "MPI_Win_allocate");
  if (ranks.rank() == 0) *window_->counter = 0;
  check(MPI_Win_fence(0, window_->window), "MPI_Win_fence");  // the zero is in place before anyone asks
}

Ranks::UnitCounter::~UnitCounter() {
  if (window_) MPI_Win_free(&window_->window);
}

std::uint64_t Ranks::UnitCounter::next() {
  if (!window_) return local_++;
  const std::uint64_t one = 1;
  std::uint64_t previous = 0;
  check(MPI_Win_lock(MPI_LOCK_SHARED, 0, 0, window_->window), "MPI_Win_lock");
  check(MPI_Fetch_and_op(&one, &previous, MPI_UINT64_T, 0, 0, MPI_SUM, window_->window), "MPI_Fetch_and_op");
  check(MPI_Win_unlock(0, window_->window), "MPI_Win_unlock");
  return previous;
}

#else  // one rank

std::unique_ptr<Ranks> Ranks::join() { return std::make_unique<Ranks>(); }
Ranks::~Ranks() = default;
void Ranks::barrier() const {}
int Ranks::max(int value) const { return value; }
std::uint64_t Ranks::max(std::uint64_t value) const { return value; }
Ranks::Failure Ranks::first_failure(bool failed, const std::string& message) const {
  return failed ? Failure{0, message} : Failure{};
}
std::string Ranks::broadcast(const std::string& text) const { return text; }
struct Ranks::UnitCounter::Window {};
Ranks::UnitCounter::UnitCounter(const Ranks&) {}
Ranks::UnitCounter::~UnitCounter() = default;
std::uint64_t Ranks::UnitCounter::next() { return local_++; }

#endif

}  // namespace nonsep::host
