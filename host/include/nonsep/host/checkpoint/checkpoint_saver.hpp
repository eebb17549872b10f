#pragma once
// checkpoint.json (checkpoint_file.hpp): saved after every `every_steps` steps and/or once `every_seconds` of wall time
// have passed since the last one (job /checkpoint), and when the run is interrupted, from the driver's state and
// every observer's save(). A run that ends otherwise removes it. Add it after the observers whose state it saves.
// The one writer of the file: its layout is written here and read back by load_checkpoint (checkpoint_file.hpp).
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "nonsep/host/job.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#include "nonsep/host/run/observer.hpp"

namespace nonsep::host {

class CheckpointSaver : public Observer, public ChunkObserver {
 public:
  // `fingerprint` and `stepping`: the job's (job_fingerprint, stepping_identity: checkpoint_file.hpp). `observers`:
  // those whose state goes into the checkpoint (not owned).
  CheckpointSaver(std::filesystem::path path, std::string fingerprint, std::string stepping,
                  const CheckpointPolicy& policy, const EnsembleDriver& driver, std::vector<Observer*> observers);

  std::uint64_t next_event(std::uint64_t step) const override;
  void after_chunk(std::uint64_t step) override;
  void before_finish(std::uint64_t step, bool interrupted) override;

  // Saves now. Throws OutputError.
  void save_now();

 private:
  using Clock = std::chrono::steady_clock;
  std::filesystem::path path_;
  std::string fingerprint_, stepping_;
  CheckpointPolicy policy_;
  const EnsembleDriver& driver_;
  std::vector<Observer*> observers_;
  Clock::time_point next_save_;
};

}  // namespace nonsep::host
