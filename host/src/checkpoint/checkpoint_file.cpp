#include "nonsep/host/checkpoint/checkpoint_file.hpp"

#include <bit>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/content_hash.hpp"
#include "nonsep/host/output/run_folder.hpp"

namespace nonsep::host {

using json = nlohmann::json;

namespace {

// Every read of a malformed file ends here, with what was wrong.
SavedState reader(const std::filesystem::path& path) {
  return SavedState(path.string(), "; run the job with --force instead of --resume to start it over");
}

void append_bits(std::string& text, double value) {
  text += std::to_string(std::bit_cast<std::uint64_t>(value));
  text += ',';
}

// What the checksum cannot catch (a checkpoint written by a faulty build, or rewritten with a fresh checksum):
// active trajectories have finite states and the status "running", retired ones another status.
void check_consistency(const SavedState& read, const DriverState& state, std::size_t n) {
  for (std::size_t i = 0; i < state.q.size(); ++i)
    if (!std::isfinite(state.q[i]) || !std::isfinite(state.p[i]))
      read.damaged("active trajectory " + std::to_string(state.active[i / n]) + " has a state that is not finite");
  std::vector<bool> active(state.records.size(), false);
  for (std::size_t index : state.active) active[index] = true;
  for (std::size_t i = 0; i < state.records.size(); ++i)
    if (active[i] != (state.records[i].status == TrajectoryStatus::running))
      read.damaged("trajectory " + std::to_string(i) +
                   (active[i] ? " is active but its record says \"" : " is not active but its record says \"") +
                   std::string(to_string(state.records[i].status)) + "\"");
}

}  // namespace

namespace {

// The plugin file's bytes, hashed: another library with the same name and version is another model.
std::uint64_t file_hash(const std::filesystem::path& path) { return file_content_hash(path).value_or(0); }

// The integrator's part: the scheme and the form; then one part per option of the scheme's catalogue entry
// ("integrator.omega"), read through option_value, so that every option of every scheme is in the fingerprint and a
// changed one is named.
void add_integrator_parts(std::vector<std::pair<std::string, std::string>>& parts, const IntegratorSpec& spec) {
  parts.emplace_back("integrator", spec.scheme + '\n' + (spec.form == HamiltonianForm::TTV ? "TTV" : "VVT"));
  const Scheme* scheme = find_scheme(spec.scheme);
  if (!scheme) return;  // the job reader refuses an unknown scheme; the name alone identifies it
  for (const ParameterDescription& option : scheme->parameters) {
    std::string text;
    std::visit(
        [&](const auto& value) {
          if constexpr (std::is_same_v<std::decay_t<decltype(value)>, Fraction>)
            text = value.to_string();
          else
            append_bits(text, value);
        },
        option_value(spec, option));
    parts.emplace_back("integrator." + option.name, text);
  }
}

// "name:hash" pairs separated by spaces.
std::map<std::string, std::string> fingerprint_parts(const std::string& fingerprint) {
  std::map<std::string, std::string> parts;
  std::istringstream words(fingerprint);
  for (std::string word; words >> word;) {
    const std::size_t colon = word.find(':');
    parts[word.substr(0, colon)] = colon == std::string::npos ? "" : word.substr(colon + 1);
  }
  return parts;
}

}  // namespace

std::string job_fingerprint(const LoadedJob& loaded) {
  const Job& job = loaded.job;
  const SingleRun& run = job.run();
  std::vector<std::pair<std::string, std::string>> parts;
  parts.emplace_back("plugin", loaded.plugin.name() + '\n' + loaded.plugin.version() + '\n' +
                                   content_hash_hex(file_hash(loaded.plugin.path())));
  parts.emplace_back("parameters", loaded.model.parameters().dump());
  add_integrator_parts(parts, run.integrator);
  if (const auto& asked = run.auto_scheme) {  // what the choice was made for (the integrator part is the chosen one)
    std::string text;
    append_bits(text, asked->tolerance);
    text += asked->measure == AutoScheme::Measure::phase ? "phase" : "energy";
    parts.emplace_back("auto", std::move(text));
  }
  std::string initial = std::to_string(job.initial.dimension) + ' ' + std::to_string(job.initial.count) + '\n';
  for (double x : job.initial.q) append_bits(initial, x);
  for (double x : job.initial.p) append_bits(initial, x);
  parts.emplace_back("initial", std::move(initial));
  if (!job.sweep.empty()) {  // each trajectory's parameters: every set's first trajectory and parameters
    std::string sweep;
    const std::vector<std::size_t>& sets = job.initial.parameter_set;
    for (std::size_t b = 0; b < sets.size(); ++b)
      if (b == 0 || sets[b] != sets[b - 1]) sweep += std::to_string(b) + ' ' + job.parameter_set(sets[b]).dump() + '\n';
    parts.emplace_back("sweep", std::move(sweep));
  }
  std::string time;
  append_bits(time, run.time.dt);
  append_bits(time, run.time.t_end);
  time += std::to_string(run.time.steps);
  parts.emplace_back("time", std::move(time));
  std::string output = std::to_string(run.every) + ' ' + std::to_string(run.energy_every);
  if (run.format == OutputFormat::hdf5) output += " hdf5";
  parts.emplace_back("output", std::move(output));
  std::string analysis;
  if (run.analysis.closest_return_after) append_bits(analysis, *run.analysis.closest_return_after);
  analysis += '|';
  if (run.analysis.max_relative_energy_error) append_bits(analysis, *run.analysis.max_relative_energy_error);
  if (const auto& section = run.analysis.poincare) {
    analysis += "|poincare ";
    for (double x : section->normal) append_bits(analysis, x);
    append_bits(analysis, section->offset);
    analysis += std::to_string(static_cast<int>(section->direction)) + ' ' +
                (section->max_crossings ? std::to_string(*section->max_crossings) : "none");
  }
  if (const auto& lyapunov = run.analysis.lyapunov)
    analysis += "|lyapunov " + std::to_string(lyapunov->vectors) + ' ' + std::to_string(lyapunov->renormalize_every) +
                ' ' + std::to_string(lyapunov->every);
  // The tangent map's indicators, then those that need samples (with the degrees of freedom they sample).
  for (const auto& indicator : run.analysis.tangent_indicators()) {
    if (indicator->name() == "lyapunov") continue;  // above
    analysis += "|" + indicator->name();
    for (const auto& [name, value] : indicator->settings()) analysis += " " + std::to_string(value);
  }
  for (const auto& indicator : run.analysis.sampled_indicators()) {
    analysis += "|" + indicator->name();
    for (const auto& [name, value] : indicator->settings()) analysis += " " + std::to_string(value);
    const SampleNeeds needs = indicator->needs().samples;
    for (std::size_t k : needs.degrees) analysis += ' ' + std::to_string(k);
  }
  if (run.analysis.error_estimate) analysis += "|error_estimate";
  parts.emplace_back("analysis", std::move(analysis));
  std::string fingerprint;
  for (const auto& [name, text] : parts)
    fingerprint += (fingerprint.empty() ? "" : " ") + name + ":" + content_hash_hex(content_hash(text));
  return fingerprint;
}

std::string fingerprint_difference(const std::string& a, const std::string& b) {
  const auto first = fingerprint_parts(a), second = fingerprint_parts(b);
  std::string differ;
  const auto add = [&](const std::string& name) { differ += (differ.empty() ? "" : ", ") + name; };
  for (const auto& [name, hash] : first)
    if (const auto other = second.find(name); other == second.end() || other->second != hash) add(name);
  for (const auto& [name, hash] : second)
    if (!first.contains(name)) add(name);
  return differ.empty() ? "the job's identity" : differ;
}

std::string what_differs(const std::string& a, const std::string& b) {
  const std::string parts = fingerprint_difference(a, b);
  return parts + (parts.find(',') == std::string::npos ? " differs" : " differ");
}

std::string stepping_identity(const LoadedJob& job) {
  const std::string set = job.plugin.kernels().chosen_name();
  return set.empty() ? "evaluation" : set;
}

namespace {

// Refuses a `recorded` stepping that differs from this process's, `current` (check_stepping).
void refuse_other_stepping(const std::string& recorded, const std::string& current, const LoadedJob& job,
                           const std::filesystem::path& written) {
  if (recorded == current) return;
  const auto path_of = [](const std::string& stepping) {
    return stepping == "evaluation" ? std::string("the evaluation path (no kernel)")
                                    : "the plugin's " + stepping + " kernel";
  };
  const KernelChoice& kernels = job.plugin.kernels();
  throw CheckpointError(written.string() + " was written by a run stepping through " + path_of(recorded) +
                        ", and this one would step through " + path_of(current) + " (" + kernels.note +
                        "): the two may round differently, so a resumed run could equal neither uninterrupted "
                        "run. Resume with NONSEP_INSTRUCTION_SET=" +
                        recorded + " (the variable that chooses the stepping), or run with --force to start over");
}

}  // namespace

void check_stepping(const std::string& recorded, const LoadedJob& job, const std::filesystem::path& written) {
  refuse_other_stepping(recorded, stepping_identity(job), job, written);
}

CheckpointIdentity checkpoint_identity(const LoadedJob& job, const nlohmann::ordered_json& scheme_choice) {
  return {job_fingerprint(job), stepping_identity(job), scheme_choice.is_null() ? "" : scheme_choice.dump()};
}

namespace {

// The checkpoint at `path` read whole and checked as a file: JSON, its format, its checksum (removed from the
// document). Throws CheckpointError.
json read_checkpoint_document(const std::filesystem::path& path) {
  std::optional<std::string> text;
  try {
    text = read_regular_file(path);
  } catch (const OutputError& error) {
    throw CheckpointError(error.what());
  }
  if (!text)
    throw CheckpointError(
        "nothing to resume: there is no " + path.string() + " (a run saves one when interrupted and " +
        "as /checkpoint says; a completed run removes it), nor the work units of a run on MPI ranks " +
        "(which it saves in " + (path.parent_path() / units_folder).string() + " before its first unit starts)");
  json document;
  // nlohmann's lexer takes a NUL byte for the end of the input: what follows one would be ignored unread.
  if (const std::size_t nul = text->find('\0'); nul != std::string::npos)
    reader(path).damaged("a NUL byte at byte offset " + std::to_string(nul) + " (counted from 0): JSON holds none");
  try {
    document = json::parse(*text);
  } catch (const json::exception& error) {
    reader(path).damaged(std::string("not JSON: ") + error.what());
  }
  const SavedState read = reader(path);
  if (read.string(read.member(document, "format"), "format") != checkpoint_format)
    read.damaged(std::string("its format is not \"") + checkpoint_format + "\"");
  const std::string checksum = read.string(read.member(document, "checksum"), "checksum");
  document.erase("checksum");
  if (checksum != checkpoint_checksum(document))
    read.damaged("its content does not match its checksum: it was edited or damaged");
  return document;
}

}  // namespace

nlohmann::ordered_json recorded_scheme_choice(const std::filesystem::path& path) {
  const json document = read_checkpoint_document(path);
  if (!document.contains("scheme_choice"))
    throw CheckpointError(path.string() +
                          " belongs to a different job: it was written by a run with a fixed integrator, not by one "
                          "of scheme \"auto\"; run with --force to start over, or resume with the job that wrote it");
  const SavedState read = reader(path);
  const nlohmann::ordered_json choice =
      nlohmann::ordered_json::parse(read.string(document["scheme_choice"], "scheme_choice"), nullptr, false);
  if (!choice.is_object()) read.damaged("its scheme_choice is not a JSON object");
  return choice;
}

Checkpoint load_checkpoint(const std::filesystem::path& path, const LoadedJob& job) {
  return load_checkpoint(path, job, checkpoint_identity(job));
}

Checkpoint load_checkpoint(const std::filesystem::path& path, const LoadedJob& loaded,
                           const CheckpointIdentity& identity) {
  const Job& job = loaded.job;
  json document = read_checkpoint_document(path);
  const SavedState read = reader(path);
  const std::string fingerprint = read.string(read.member(document, "job_fingerprint"), "job_fingerprint");
  if (fingerprint != identity.fingerprint)
    throw CheckpointError(
        path.string() + " belongs to a different job: its " + what_differs(fingerprint, identity.fingerprint) +
        " (the plugin part covers the plugin file's bytes, integrator.NAME is the integrator's option NAME, "
        "output covers output.every, energy_every and format, auto scheme auto's tolerance and measure); run with "
        "--force to start over, or resume with the "
        "job that wrote it");
  refuse_other_stepping(read.string(read.member(document, "stepping"), "stepping"), identity.stepping, loaded, path);
  Checkpoint checkpoint;
  DriverState& state = checkpoint.driver;
  const std::size_t n = job.initial.dimension;
  state.step = read.count(read.member(document, "step"), "step");
  if (state.step > job.run().time.steps) read.damaged("its step is beyond the job's last step");
  const json& evaluations = read.member(document, "evaluations");
  state.evaluations.grad_T = read.count(read.member(evaluations, "grad_T"), "evaluations");
  state.evaluations.grad_V = read.count(read.member(evaluations, "grad_V"), "evaluations");
  state.evaluations.grad_H = read.count(read.member(evaluations, "grad_H"), "evaluations");
  if (evaluations.contains("grad_K") || evaluations.contains("grad_U")) {
    state.evaluations.grad_K = read.count(read.member(evaluations, "grad_K"), "evaluations");
    state.evaluations.grad_U = read.count(read.member(evaluations, "grad_U"), "evaluations");
  }
  const json& active = read.member(document, "active");
  const json& trajectories = read.member(active, "trajectories");
  if (!trajectories.is_array()) read.damaged("active.trajectories is not an array");
  std::optional<std::size_t> previous;
  for (const auto& entry : trajectories) {
    const auto index = read.count(entry, "active.trajectories");
    if (index >= job.initial.count || (previous && index <= *previous))
      read.damaged("active.trajectories is not increasing trajectory indices of the job");
    previous = static_cast<std::size_t>(index);
    state.active.push_back(static_cast<std::size_t>(index));
  }
  state.q = read.numbers(read.member(active, "q"), state.active.size() * n, "active.q");
  state.p = read.numbers(read.member(active, "p"), state.active.size() * n, "active.p");
  state.energies = read.numbers(read.member(active, "energies"), state.active.size(), "active.energies");
  const std::size_t k = job.run().analysis.tangent_vectors(), tangent_size = state.active.size() * k * n;
  state.tangent_q = read.numbers(read.member(active, "tangent_q"), tangent_size, "active.tangent_q");
  state.tangent_p = read.numbers(read.member(active, "tangent_p"), tangent_size, "active.tangent_p");
  // The scheme's private state, as the scheme names and sizes it (nothing for most schemes).
  state.scheme = scheme_state_layout(job.run().integrator, k, n);
  for (SchemeState::Column& column : state.scheme.columns) {
    const std::string what = "active." + column.name;
    column.values = read.numbers(read.member(active, column.name), state.active.size() * column.per_state, what);
  }
  for (SchemeState::Largest& number : state.scheme.largest)
    number.value = read.number(read.member(document, number.name), number.name);
  const json& lyapunov = read.member(active, "lyapunov");
  if (!lyapunov.is_array() || lyapunov.size() != (k > 0 ? state.active.size() : 0))
    read.damaged("active.lyapunov does not have one entry per active trajectory");
  for (const json& entry : lyapunov) {
    const auto l = read.numbers(entry, 5 + k, "active.lyapunov");
    LyapunovRecord record;
    record.steps = static_cast<std::uint64_t>(l[0]);
    record.steps_since_renormalization = static_cast<std::uint64_t>(l[1]);
    record.time = l[2];
    record.time_since_renormalization = l[3];
    record.log_norm_first = l[4];
    std::copy(l.begin() + 5, l.end(), record.log_stretch.begin());
    state.lyapunov.push_back(record);
  }
  // Each indicator's state under its name, as the run's indicators size it.
  const IndicatorList indicators = k > 0 ? job.run().analysis.tangent_indicators() : IndicatorList();
  const json& saved_indicators = read.member(active, "indicators");
  if (!saved_indicators.is_object() || saved_indicators.size() != indicators.size())
    read.damaged("active.indicators does not have the states of the job's indicators");
  std::size_t columns = 0;
  for (const auto& indicator : indicators) {
    const std::string what = "active.indicators." + indicator->name();
    state.indicators.push_back(
        {indicator->name(), read.numbers(read.member(saved_indicators, indicator->name()),
                                         state.active.size() * indicator->needs().state_size, what)});
    columns += indicator->columns().size();
  }
  const json& records = read.member(document, "records");
  if (!records.is_array() || records.size() != job.initial.count)
    read.damaged("it does not have one record per trajectory");
  for (const auto& entry : records) {
    TrajectoryRecord record;
    const auto status = trajectory_status_from_string(read.string(read.member(entry, "status"), "status"));
    if (!status) read.damaged("a record's status is not a trajectory status");
    record.status = *status;
    record.final_step = read.count(read.member(entry, "final_step"), "final_step");
    record.final_t = read.number(read.member(entry, "final_t"), "final_t");
    const json& final_q = read.member(entry, "final_q");
    const std::size_t final_size = final_q.is_array() && final_q.empty() ? 0 : n;
    record.final_q = read.numbers(final_q, final_size, "final_q");
    record.final_p = read.numbers(read.member(entry, "final_p"), final_size, "final_p");
    record.energy_initial = read.optional_number(read.member(entry, "energy_initial"), "energy_initial");
    record.energy_final = read.optional_number(read.member(entry, "energy_final"), "energy_final");
    record.stop_step = read.count(read.member(entry, "stop_step"), "stop_step");
    record.stop_t = read.number(read.member(entry, "stop_t"), "stop_t");
    record.stop_variable = read.string(read.member(entry, "stop_variable"), "stop_variable");
    record.message = read.string(read.member(entry, "message"), "message");
    const json& values = read.member(entry, "indicators");
    record.indicators = read.numbers(values, values.is_array() && values.empty() ? 0 : columns, "indicators");
    state.records.push_back(std::move(record));
  }
  check_consistency(read, state, n);
  checkpoint.observers = read.member(document, "observers");
  if (!checkpoint.observers.is_object()) read.damaged("observers is not an object");
  return checkpoint;
}

}  // namespace nonsep::host
