#include "nonsep/host/checkpoint/checkpoint_saver.hpp"

#include "nonsep/host/checkpoint/checkpoint_file.hpp"
#include "nonsep/host/output/atomic_files.hpp"

namespace nonsep::host {

CheckpointSaver::CheckpointSaver(std::filesystem::path path, std::string fingerprint, const CheckpointPolicy& policy,
                                 const EnsembleDriver& driver, std::vector<Observer*> observers)
    : path_(std::move(path)),
      fingerprint_(std::move(fingerprint)),
      policy_(policy),
      driver_(driver),
      observers_(std::move(observers)),
      next_save_(Clock::now() +
                 std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(policy.every_seconds))) {}

std::uint64_t CheckpointSaver::next_event(std::uint64_t step) const {
  return policy_.every_steps > 0 ? (step / policy_.every_steps + 1) * policy_.every_steps : no_event;
}

void CheckpointSaver::after_chunk(std::uint64_t step) {
  const bool by_steps = policy_.every_steps > 0 && step % policy_.every_steps == 0;
  const bool by_time = policy_.every_seconds > 0.0 && Clock::now() >= next_save_;
  if (by_steps || by_time) save_now();
}

void CheckpointSaver::before_finish(std::uint64_t, bool interrupted) {
  if (interrupted) {
    save_now();
    return;
  }
  remove_file(path_);
}

void CheckpointSaver::save_now() {
  Checkpoint checkpoint;
  for (Observer* each : observers_)
    if (auto* observer = dynamic_cast<CheckpointedObserver*>(each); observer && !observer->name().empty())
      checkpoint.observers[observer->name()] = observer->save();
  checkpoint.driver = driver_.state();
  save_checkpoint(path_, checkpoint, fingerprint_);
  next_save_ =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(policy_.every_seconds));
}

}  // namespace nonsep::host
