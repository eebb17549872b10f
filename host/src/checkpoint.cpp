#include "nonsep/host/checkpoint.hpp"

#include <bit>
#include <charconv>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "nonsep/host/number_format.hpp"
#include "nonsep/host/output_files.hpp"

namespace nonsep::host {

using json = nlohmann::json;

namespace {

constexpr const char* format_tag = "nonsep checkpoint 1";

json encode(double value) { return format_number(value); }

json encode(const std::vector<double>& values) {
  json list = json::array();
  for (double value : values) list.push_back(encode(value));
  return list;
}

json encode(const std::optional<double>& value) { return value ? encode(*value) : json(nullptr); }

// Every read of a malformed file ends here, with what was wrong.
[[noreturn]] void damaged(const std::filesystem::path& path, const std::string& what) {
  throw CheckpointError(path.string() + " is damaged (" + what + "); run the job without --resume to start it over");
}

struct Reader {
  const std::filesystem::path& path;

  double number(const json& value, const char* what) const {
    if (!value.is_string()) damaged(path, std::string(what) + " is not a number");
    const std::string& text = value.get_ref<const std::string&>();
    double x = 0.0;
    const auto result = std::from_chars(text.data(), text.data() + text.size(), x);
    if (result.ec != std::errc() || result.ptr != text.data() + text.size())
      damaged(path, std::string(what) + " is not a number: \"" + text + "\"");
    return x;
  }
  std::optional<double> optional_number(const json& value, const char* what) const {
    if (value.is_null()) return std::nullopt;
    return number(value, what);
  }
  std::vector<double> numbers(const json& value, std::size_t size, const char* what) const {
    if (!value.is_array() || value.size() != size)
      damaged(path, std::string(what) + " does not have " + std::to_string(size) + " numbers");
    std::vector<double> result;
    result.reserve(size);
    for (const auto& x : value) result.push_back(number(x, what));
    return result;
  }
  std::uint64_t unsigned_integer(const json& value, const char* what) const {
    if (!value.is_number_unsigned()) damaged(path, std::string(what) + " is not an integer >= 0");
    return value.get<std::uint64_t>();
  }
  std::string string(const json& value, const char* what) const {
    if (!value.is_string()) damaged(path, std::string(what) + " is not a string");
    return value.get<std::string>();
  }
  const json& member(const json& object, const char* key) const {
    if (!object.is_object() || !object.contains(key)) damaged(path, std::string("\"") + key + "\" is missing");
    return object.at(key);
  }
};

void append_bits(std::string& text, double value) {
  text += std::to_string(std::bit_cast<std::uint64_t>(value));
  text += ',';
}

}  // namespace

std::string job_fingerprint(const LoadedJob& loaded) {
  const Job& job = loaded.job;
  std::string text = loaded.plugin.name() + '\n' + loaded.plugin.version() + '\n' + loaded.model.parameters().dump() +
                     '\n' + job.integrator.scheme + '\n' + job.integrator.order.to_string() + '\n';
  append_bits(text, job.integrator.t2);
  text += job.integrator.form == HamiltonianForm::TTV ? "TTV\n" : "VVT\n";
  text += std::to_string(job.initial.dimension) + ' ' + std::to_string(job.initial.count) + '\n';
  for (double x : job.initial.q) append_bits(text, x);
  for (double x : job.initial.p) append_bits(text, x);
  append_bits(text, job.time.dt);
  append_bits(text, job.time.t_end);
  text += std::to_string(job.time.steps) + ' ' + std::to_string(job.every) + '\n';
  if (job.analysis.closest_return_after) append_bits(text, *job.analysis.closest_return_after);
  std::uint64_t hash = 14695981039346656037ull;
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  char digits[17];
  std::snprintf(digits, sizeof digits, "%016llx", static_cast<unsigned long long>(hash));
  return digits;
}

void save_checkpoint(const std::filesystem::path& path, const RunState& state, const std::string& fingerprint) {
  json records = json::array();
  for (const TrajectoryRecord& record : state.records)
    records.push_back(
        {{"status", record.status},
         {"final_step", record.final_step},
         {"final_t", encode(record.final_t)},
         {"final_q", encode(record.final_q)},
         {"final_p", encode(record.final_p)},
         {"energy_initial", encode(record.energy_initial)},
         {"energy_final", encode(record.energy_final)},
         {"max_abs_relative_error", encode(record.max_abs_relative_error)},
         {"last_written_step", record.last_written_step ? json(*record.last_written_step) : json(nullptr)},
         {"diverged_step", record.diverged_step},
         {"diverged_t", encode(record.diverged_t)},
         {"diverged_variable", record.diverged_variable},
         {"error", record.error},
         {"closest_distance", encode(record.closest_distance)},
         {"closest_step", record.closest_step},
         {"closest_t", encode(record.closest_t)}});
  const json document = {
      {"format", format_tag},
      {"job_fingerprint", fingerprint},
      {"step", state.step},
      {"trajectory_bytes", state.trajectory_bytes},
      {"evaluations", {{"grad_T", state.evaluations.grad_T}, {"grad_V", state.evaluations.grad_V}}},
      {"active",
       {{"slots", state.slots}, {"q", encode(state.q)}, {"p", encode(state.p)}, {"energies", encode(state.energies)}}},
      {"records", std::move(records)}};
  write_file_atomically(path, document.dump() + "\n");
}

RunState load_checkpoint(const std::filesystem::path& path, const LoadedJob& loaded) {
  const Job& job = loaded.job;
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw CheckpointError("nothing to resume: there is no " + path.string() +
                          " (a run saves one when interrupted and as /checkpoint says; a completed run removes it)");
  std::ostringstream text;
  text << in.rdbuf();
  json document;
  try {
    document = json::parse(text.str());
  } catch (const json::exception& error) {
    damaged(path, std::string("not JSON: ") + error.what());
  }
  const Reader read{path};
  if (read.string(read.member(document, "format"), "format") != format_tag)
    damaged(path, std::string("its format is not \"") + format_tag + "\"");
  const std::string fingerprint = read.string(read.member(document, "job_fingerprint"), "job_fingerprint");
  if (fingerprint != job_fingerprint(loaded))
    throw CheckpointError(path.string() + " belongs to a different job (fingerprint " + fingerprint + ", this job " +
                          job_fingerprint(loaded) +
                          "): the model, its parameters, the integrator, the initial states, the time grid or "
                          "output.every differ; run without --resume to start over, or resume with the job that "
                          "wrote it");
  RunState state;
  const std::size_t n = job.initial.dimension;
  state.step = read.unsigned_integer(read.member(document, "step"), "step");
  if (state.step > job.time.steps) damaged(path, "its step is beyond the job's last step");
  state.trajectory_bytes = read.unsigned_integer(read.member(document, "trajectory_bytes"), "trajectory_bytes");
  const json& evaluations = read.member(document, "evaluations");
  state.evaluations.grad_T = read.unsigned_integer(read.member(evaluations, "grad_T"), "evaluations");
  state.evaluations.grad_V = read.unsigned_integer(read.member(evaluations, "grad_V"), "evaluations");
  const json& active = read.member(document, "active");
  const json& slots = read.member(active, "slots");
  if (!slots.is_array()) damaged(path, "active.slots is not an array");
  std::vector<bool> seen(job.initial.count, false);
  for (const auto& slot : slots) {
    const auto index = read.unsigned_integer(slot, "active.slots");
    if (index >= job.initial.count || seen[index]) damaged(path, "active.slots names a trajectory twice or not at all");
    seen[index] = true;
    state.slots.push_back(static_cast<std::size_t>(index));
  }
  state.q = read.numbers(read.member(active, "q"), state.slots.size() * n, "active.q");
  state.p = read.numbers(read.member(active, "p"), state.slots.size() * n, "active.p");
  state.energies = read.numbers(read.member(active, "energies"), state.slots.size(), "active.energies");
  const json& records = read.member(document, "records");
  if (!records.is_array() || records.size() != job.initial.count)
    damaged(path, "it does not have one record per trajectory");
  for (const auto& entry : records) {
    TrajectoryRecord record;
    record.status = read.string(read.member(entry, "status"), "status");
    record.final_step = read.unsigned_integer(read.member(entry, "final_step"), "final_step");
    record.final_t = read.number(read.member(entry, "final_t"), "final_t");
    const json& final_q = read.member(entry, "final_q");
    const std::size_t final_size = final_q.is_array() && final_q.empty() ? 0 : n;
    record.final_q = read.numbers(final_q, final_size, "final_q");
    record.final_p = read.numbers(read.member(entry, "final_p"), final_size, "final_p");
    record.energy_initial = read.optional_number(read.member(entry, "energy_initial"), "energy_initial");
    record.energy_final = read.optional_number(read.member(entry, "energy_final"), "energy_final");
    record.max_abs_relative_error = read.number(read.member(entry, "max_abs_relative_error"), "max_abs_relative_error");
    if (const json& last = read.member(entry, "last_written_step"); !last.is_null())
      record.last_written_step = read.unsigned_integer(last, "last_written_step");
    record.diverged_step = read.unsigned_integer(read.member(entry, "diverged_step"), "diverged_step");
    record.diverged_t = read.number(read.member(entry, "diverged_t"), "diverged_t");
    record.diverged_variable = read.string(read.member(entry, "diverged_variable"), "diverged_variable");
    record.error = read.string(read.member(entry, "error"), "error");
    record.closest_distance = read.optional_number(read.member(entry, "closest_distance"), "closest_distance");
    record.closest_step = read.unsigned_integer(read.member(entry, "closest_step"), "closest_step");
    record.closest_t = read.number(read.member(entry, "closest_t"), "closest_t");
    state.records.push_back(std::move(record));
  }
  return state;
}

}  // namespace nonsep::host
