#include "nonsep/host/checkpoint/checkpoint_saver.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "nonsep/host/number_format.hpp"
#include "nonsep/host/output/atomic_files.hpp"

namespace nonsep::host {

using json = nlohmann::json;

namespace {

json encode(double value) { return format_number(value); }

json encode(const std::vector<double>& values) {
  json list = json::array();
  for (double value : values) list.push_back(encode(value));
  return list;
}

json encode(const std::optional<double>& value) { return value ? encode(*value) : json(nullptr); }

// A LyapunovRecord as numbers: steps, steps since renormalisation, time, time since, ln |v_1|, then the k sums.
json encode(const LyapunovRecord& record, std::size_t k) {
  std::vector<double> numbers{static_cast<double>(record.steps),
                              static_cast<double>(record.steps_since_renormalization), record.time,
                              record.time_since_renormalization, record.log_norm_first};
  numbers.insert(numbers.end(), record.log_stretch.begin(),
                 record.log_stretch.begin() + static_cast<std::ptrdiff_t>(k));
  return encode(numbers);
}
// Writes checkpoint.json (checkpoint_file.hpp describes it) atomically. Throws OutputError.
void save_checkpoint(const std::filesystem::path& path, const DriverState& state, const json& observers,
                     const CheckpointIdentity& identity) {
  json records = json::array();
  for (const TrajectoryRecord& record : state.records)
    records.push_back({{"status", to_string(record.status)},
                       {"final_step", record.final_step},
                       {"final_t", encode(record.final_t)},
                       {"final_q", encode(record.final_q)},
                       {"final_p", encode(record.final_p)},
                       {"energy_initial", encode(record.energy_initial)},
                       {"energy_final", encode(record.energy_final)},
                       {"stop_step", record.stop_step},
                       {"stop_t", encode(record.stop_t)},
                       {"stop_variable", record.stop_variable},
                       {"message", record.message},
                       {"indicators", encode(record.indicators)}});
  json lyapunov = json::array();
  const std::size_t k = state.active.empty() ? 0 : state.tangent_q.size() / std::max<std::size_t>(1, state.q.size());
  for (const LyapunovRecord& record : state.lyapunov) lyapunov.push_back(encode(record, k));
  json indicator_states = json::object();
  for (const DriverState::IndicatorState& indicator : state.indicators)
    indicator_states[indicator.name] = encode(indicator.values);
  json evaluations = {
      {"grad_T", state.evaluations.grad_T}, {"grad_V", state.evaluations.grad_V}, {"grad_H", state.evaluations.grad_H}};
  // The separable part's counts, only for a model that has one (the checkpoints of other models are unchanged).
  if (state.evaluations.grad_K + state.evaluations.grad_U > 0) {
    evaluations["grad_K"] = state.evaluations.grad_K;
    evaluations["grad_U"] = state.evaluations.grad_U;
  }
  json document = {{"format", checkpoint_format},
                   {"job_fingerprint", identity.fingerprint},
                   {"stepping", identity.stepping},
                   {"step", state.step},
                   {"evaluations", evaluations},
                   {"active",
                    {{"trajectories", state.active},
                     {"q", encode(state.q)},
                     {"p", encode(state.p)},
                     {"energies", encode(state.energies)},
                     {"tangent_q", encode(state.tangent_q)},
                     {"tangent_p", encode(state.tangent_p)},
                     {"lyapunov", std::move(lyapunov)},
                     {"indicators", std::move(indicator_states)}}},
                   {"records", std::move(records)},
                   {"observers", observers}};
  // The scheme's private state, under the names it gives: its columns with the active trajectories', its numbers
  // about the run at the top.
  for (const SchemeState::Column& column : state.scheme.columns)
    document["active"][column.name] = encode(column.values);
  for (const SchemeState::Largest& number : state.scheme.largest) document[number.name] = encode(number.value);
  if (!identity.scheme_choice.empty()) document["scheme_choice"] = identity.scheme_choice;
  // Signed in place (the checksum is of the document without it): a copy would double the checkpoint's memory.
  document["checksum"] = checkpoint_checksum(document);
  std::string text = document.dump();
  document = json();  // freed before the text is written
  text += '\n';
  write_file_atomically(path, text);
}

}  // namespace

CheckpointSaver::CheckpointSaver(std::filesystem::path path, CheckpointIdentity identity,
                                 const CheckpointPolicy& policy, const EnsembleDriver& driver,
                                 std::vector<CheckpointedObserver*> observers)
    : path_(std::move(path)),
      identity_(std::move(identity)),
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
  json observers = json::object();
  for (CheckpointedObserver* observer : observers_)
    if (!observer->name().empty()) observers[observer->name()] = observer->save();
  save_checkpoint(path_, driver_.state(), observers, identity_);
  next_save_ =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(policy_.every_seconds));
}

}  // namespace nonsep::host
