// Pass 2 of the job reader: the whole document, section by section (sections.hpp), and the rules that join
// sections: a study has no /integrator, /analysis or /checkpoint, one initial state, and a reference of its
// dimension.
#include "sections.hpp"

namespace nonsep::host {

using namespace job_reader;

Job parse_job(const nlohmann::json& document, const std::filesystem::path& job_file, std::vector<JobIssue>& issues) {
  Checker check(issues);
  Job job;
  job.file = job_file;
  job.directory = job_file.parent_path().empty() ? std::filesystem::path(".") : job_file.parent_path();
  if (!check.object(document, "",
                    "a JSON object with the keys model, integrator, initial, time (README.md, section Running nonsep)"))
    return job;
  check.known_keys(document, "",
                   {"$schema", "description", "model", "hamiltonian", "integrator", "initial", "time", "output",
                    "analysis", "study", "checkpoint"});
  if (const json* value = check.member(document, "", "$schema", false, ""))
    check.string(*value, "/$schema", "a string (the JSON Schema the file follows; ignored by nonsep)");
  if (const json* value = check.member(document, "", "description", false, ""))
    if (!value->is_string()) check.issue("/description", describe(*value), "a string (free text, ignored by nonsep)");

  read_model(check, document, job);
  const HamiltonianForm form = read_hamiltonian(check, document);
  job.initial = read_initial(check, document);
  if (const json* study = check.member(document, "", "study", false, "")) {
    if (document.contains("integrator"))
      check.issue("/integrator", "an integrator together with /study",
                  "no /integrator in a study: each entry of /study/integrators is one");
    if (document.contains("analysis"))
      check.issue("/analysis", "an analysis together with /study", "/analysis in single runs only");
    if (document.contains("checkpoint"))
      check.issue("/checkpoint", "a checkpoint policy together with /study",
                  "/checkpoint in single runs only (a study is not resumed)");
    job.integrator.form = form;
    job.time = read_study_time(check, document);
    job.study = read_study(check, *study, form, job.time.t_end);
    if (job.initial.count > 1)
      check.issue("/initial", std::to_string(job.initial.count) + " states",
                  "one state: a study runs every integrator from the same initial state");
    if (!job.study->reference_q.empty() && job.initial.dimension != 0 &&
        job.study->reference_q.size() != job.initial.dimension)
      check.issue("/study/reference/q", std::to_string(job.study->reference_q.size()) + " components",
                  std::to_string(job.initial.dimension) + ", as many as the initial state has");
  } else {
    job.integrator = read_integrator(check, document, form);
    job.time = read_time(check, document);
    if (const json* analysis = check.member(document, "", "analysis", false, ""))
      job.analysis = read_analysis(check, *analysis, job.initial.dimension);
  }
  read_output(check, document, job);
  if (const json* checkpoint = check.member(document, "", "checkpoint", false, ""))
    job.checkpoint = read_checkpoint(check, *checkpoint);
  return job;
}

}  // namespace nonsep::host
