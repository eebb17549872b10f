// Pass 2 of the job reader: the whole document, section by section (sections.hpp), and the rules that join
// sections: a study has no /integrator, /analysis or /checkpoint, one initial state, and a reference of its
// dimension.
#include "nonsep/host/platform/installation.hpp"
#include "sections.hpp"

namespace nonsep::host {

using namespace job_reader;

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
      check.issue("/study/reference/q", std::to_string(study.reference_q.size()) + " components",
                  std::to_string(job.initial.dimension) + ", as many as the initial state has");
  } else {
    SingleRun& run = job.plan.emplace<SingleRun>();
    run.integrator = read_integrator(check, keys, form, run.auto_scheme);
    run.time = read_time(check, keys);
    if (const json* analysis = keys.value("analysis"))
      run.analysis = read_analysis(check, *analysis, job.initial.dimension);
    if (const auto& frequencies = run.analysis.frequencies; frequencies && run.time.steps > 0) {
      if (run.time.steps / frequencies->every < minimum_frequency_samples)
        check.issue("/analysis/frequencies/every",
                    std::to_string(frequencies->every) + " (" + std::to_string(run.time.steps / frequencies->every) +
                        " samples of " + std::to_string(run.time.steps) + " steps)",
                    "at most steps / " + std::to_string(minimum_frequency_samples) + " = " +
                        std::to_string(run.time.steps / minimum_frequency_samples) + ": at least " +
                        std::to_string(minimum_frequency_samples) + " samples, 16 in each half of the run");
      else if (frequencies->spectra > run.time.steps / frequencies->every / 4)
        check.issue("/analysis/frequencies/spectra",
                    std::to_string(frequencies->spectra) + " (of " +
                        std::to_string(run.time.steps / frequencies->every) + " samples)",
                    "at most samples / 4 = " + std::to_string(run.time.steps / frequencies->every / 4) +
                        ": the window's main lobe is 4 frequency bins wide, so no more terms can be told apart");
    }
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
