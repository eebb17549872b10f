#pragma once
// checkpoint.json (checkpoint_file.hpp): saved after every `every_steps` steps and/or once `every_seconds` of wall time
// have passed since the last one (job /checkpoint), and when the run is interrupted, from the driver's state and
// every observer's save(). A run that ends otherwise removes it. Add it after the observers whose state it saves.
// The one writer of the file: it owns the file's format (its name, layout, format key and checksum, below), which
// load_checkpoint (checkpoint_file.hpp) reads back; it writes with nothing but what it is handed.
#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "nonsep/host/job.hpp"
#include "nonsep/host/output/content_hash.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#include "nonsep/host/run/observer.hpp"

namespace nonsep::host {

// The file name inside a run's output folder.
inline constexpr const char* checkpoint_file_name = "checkpoint.json";

// The value of the file's "format" key; a checkpoint with another is refused.
// 4: the scheme's private state, grad H; 5: "stepping" (stepping_identity); 6: the runaway check's extents and
// whether H was evaluated after step 0 (energy_error); 7: the chaos indicators' states under their names
// (active.indicators) and their final values as one list per record (records[].indicators).
inline constexpr const char* checkpoint_format = "nonsep checkpoint 7";
// The value of the file's "checksum" key: the content hash of everything else, as dumped (keys sorted, numbers as
// strings), so that an edited or damaged checkpoint is refused instead of changing the results.
inline std::string checkpoint_checksum(const nlohmann::json& document) {
  return content_hash_hex(content_hash(document.dump()));
}

// What a checkpoint says of the job it belongs to (checkpoint_identity, checkpoint_file.hpp): its "job_fingerprint"
// and "stepping" keys.
struct CheckpointIdentity {
  std::string fingerprint;  // job_fingerprint
  std::string stepping;     // stepping_identity
  // Scheme "auto": what its pilots chose (study/scheme_choice.hpp to_json), as JSON text (its keys in their order),
  // the "scheme_choice" key that a resumed run reuses instead of running the pilots again; "" without "auto".
  std::string scheme_choice;
};

class CheckpointSaver : public Observer, public ChunkObserver {
 public:
  // `identity`: the job's (checkpoint_identity). `observers`: those whose state goes into the checkpoint, under
  // their name() (not owned; one with an empty name has none).
  CheckpointSaver(std::filesystem::path path, CheckpointIdentity identity, const CheckpointPolicy& policy,
                  const EnsembleDriver& driver, std::vector<CheckpointedObserver*> observers);

  std::uint64_t next_event(std::uint64_t step) const override;
  void after_chunk(std::uint64_t step) override;
  void before_finish(std::uint64_t step, bool interrupted) override;

  // Saves now. Throws OutputError.
  void save_now();

 private:
  using Clock = std::chrono::steady_clock;
  std::filesystem::path path_;
  CheckpointIdentity identity_;
  CheckpointPolicy policy_;
  const EnsembleDriver& driver_;
  std::vector<CheckpointedObserver*> observers_;
  Clock::time_point next_save_;
};

}  // namespace nonsep::host
