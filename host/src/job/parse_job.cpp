// Pass 2 of the job reader: the whole document, section by section (sections.hpp), and the rules that join
// sections: a study has no /integrator, /analysis or /checkpoint, one initial state, and a reference of its
// dimension.
#include "nonsep/core/analysis/frequency_map_indicator.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/platform/installation.hpp"
#include "sections.hpp"

namespace nonsep::host {

using namespace job_reader;

namespace {

// What the run's steps leave an indicator that needs samples: at least the fewest it analyses; for a frequency map,
// at most a quarter of them as spectral terms.
void check_samples(Checker& check, const SingleRun& run) {
  const std::uint64_t steps = run.time.steps;
  for (const auto& indicator : run.analysis.sampled_indicators()) {
    const SampleNeeds needs = indicator->needs().samples;
    const std::string path = "/analysis/" + indicator->name();
    const std::uint64_t samples = steps / needs.every, least = needs.minimum;
    const auto* map = dynamic_cast<const FrequencyMapIndicator*>(indicator.get());
    if (samples < least)
      check.issue(path + "/every",
                  std::to_string(needs.every) + " (" + std::to_string(samples) + " samples of " +
                      std::to_string(steps) + " steps)",
                  "at most steps / " + std::to_string(least) + " = " + std::to_string(steps / least) + ": at least " +
                      std::to_string(least) + " samples, " + std::to_string(least / 2) + " in each half of the run");
    else if (map && map->spectra() > samples / 4)
      check.issue(path + "/spectra", std::to_string(map->spectra()) + " (of " + std::to_string(samples) + " samples)",
                  "at most samples / 4 = " + std::to_string(samples / 4) +
                      ": the window's main lobe is 4 frequency bins wide, so no more terms can be told apart");
  }
}

}  // namespace

Job parse_job(const nlohmann::json& document, const std::filesystem::path& job_file, std::vector<JobIssue>& issues) {
  Checker check(issues);
  Job job;
  job.file = job_file;
  job.directory = job_file.parent_path().empty() ? std::filesystem::path(".") : job_file.parent_path();
  const KeyReader keys(check, document, "", document_keys(),
                       "a JSON object with the keys model, integrator, initial, time (" + manual_location() +
                           " and its docs/user-guide.md)");
  if (!keys.is_object()) return job;
  read_model(check, keys, job);
  const HamiltonianForm form = read_hamiltonian(keys);
  job.initial = read_initial(check, keys, job.directory);
  if (const json* study_value = keys.value("study")) {
    for (const KeyRule& rule : document_keys().rules)
      if (rule.run_only && document.contains(rule.name))
        check.issue(child("", rule.name), rule.in_study_found, rule.in_study_allowed);
    const double t_end = read_study_time(check, keys).t_end;
    Study& study = job.plan.emplace<Study>(read_study(check, *study_value, form, t_end));
    study.form = form;
    study.t_end = t_end;
    for (const SweptParameter& swept : job.sweep)
      check.issue(child("/model/parameters", swept.name), std::to_string(swept.values.size()) + " values (a sweep)",
                  "one value: a study runs one parameter set (write one study per value)");
    if (job.initial.count > 1)
      check.issue("/initial", std::to_string(job.initial.count) + " states",
                  "one state: a study runs every integrator from the same initial state");
    if (!study.reference_q.empty() && job.initial.dimension != 0 && study.reference_q.size() != job.initial.dimension)
      check.issue("/study/reference/q", counted(study.reference_q.size(), "component"),
                  std::to_string(job.initial.dimension) + ", as many as the initial state has");
  } else {
    SingleRun& run = job.plan.emplace<SingleRun>();
    run.integrator = read_integrator(check, keys, form, run.auto_scheme);
    run.time = read_time(check, keys);
    if (const json* analysis = keys.value("analysis"))
      run.analysis = read_analysis(check, *analysis, job.initial.dimension);
    if (run.time.steps > 0) check_samples(check, run);
    check_sweep_size(check, job);
  }
  read_output(check, keys, job);
  if (const json* checkpoint = keys.value("checkpoint")) {
    const CheckpointPolicy policy = read_checkpoint(check, *checkpoint);  // refused above in a study
    if (!job.is_study()) std::get<SingleRun>(job.plan).checkpoint = policy;
  }
  return job;
}

}  // namespace nonsep::host
