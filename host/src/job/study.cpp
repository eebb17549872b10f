// /study: a convergence study's integrators, their step counts (per integrator or shared; counts, or step sizes
// turned into counts by step_count), and the optional exact reference state at t_end.
#include <algorithm>

#include "nonsep/core/base/error.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

namespace {

// A list of step counts (`key` "steps") or step sizes (`key` "dt") at `path`, as distinct increasing step counts
// over `t_end` (0 when the end time is invalid: the sizes are then only checked).
std::optional<std::vector<std::uint64_t>> read_step_list(Checker& check, const json& value, const std::string& path,
                                                         const std::string& key, double t_end) {
  const bool counts = key == "steps";
  const std::string what = counts ? "a non-empty array of step counts, integers from 1 to " + std::to_string(max_steps)
                                  : "a non-empty array of step sizes, finite non-zero numbers of the sign of t_end";
  if (!value.is_array() || value.empty()) {
    check.issue(path, describe(value), what);
    return std::nullopt;
  }
  std::vector<std::uint64_t> result;
  bool ok = true;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string item = child(path, i);
    if (counts) {
      const auto n = check.integer(value[i], item, 1, static_cast<std::int64_t>(max_steps),
                                   "a step count, an integer from 1 to " + std::to_string(max_steps));
      if (n)
        result.push_back(static_cast<std::uint64_t>(*n));
      else
        ok = false;
      continue;
    }
    const auto dt = check.finite_number(value[i], item, "a step size, a finite non-zero number");
    if (!dt) {
      ok = false;
      continue;
    }
    if (*dt == 0.0 || (t_end != 0.0 && !(t_end / *dt > 0.0))) {
      check.issue(item, describe(value[i]), "a non-zero step size of the same sign as /time/t_end");
      ok = false;
      continue;
    }
    if (t_end == 0.0) continue;
    if (const auto steps = step_count(check, t_end, *dt, item, describe(value[i]) + " to /time/t_end"))
      result.push_back(*steps);
    else
      ok = false;
  }
  if (!ok) return std::nullopt;
  std::sort(result.begin(), result.end());
  if (std::adjacent_find(result.begin(), result.end()) != result.end()) {
    check.issue(path, describe(value) + ", which gives the same step count twice",
                "distinct step " + std::string(counts ? "counts" : "sizes (each gives ceil(t_end / dt) steps)"));
    return std::nullopt;
  }
  return result;
}

// "steps" or "dt" (exactly one) inside `object` at `path`; `required` when the object must give one. `from` is set
// to `from_prefix` + the key used.
std::optional<std::vector<std::uint64_t>> read_steps_or_dt(Checker& check, const json& object, const std::string& path,
                                                           double t_end, bool required, std::string& from,
                                                           const std::string& from_prefix) {
  const bool has_steps = object.contains("steps"), has_dt = object.contains("dt");
  if (has_steps && has_dt) {
    check.issue(child(path, "dt"), describe(object["dt"]) + " together with " + child(path, "steps"),
                "either \"steps\" (step counts over t_end) or \"dt\" (step sizes), not both");
    return std::nullopt;
  }
  if (!has_steps && !has_dt) {
    if (required)
      check.issue(child(path, "steps"), "nothing (neither \"steps\" nor \"dt\" is given)",
                  "\"steps\": [step counts over /time/t_end] or \"dt\": [step sizes]");
    return std::nullopt;
  }
  const std::string key = has_steps ? "steps" : "dt";
  from = from_prefix + key;
  return read_step_list(check, object[key], child(path, key), key, t_end);
}

// The label of an integrator without "label": the scheme alone for a Chin scheme with one order (basic), else the
// scheme and the order of what the scheme builds from the spec, as summary.json reports it ("gauss 6" for 3 stages,
// "implicit_midpoint 2"); the scheme alone when it refuses the spec (the reader reports why).
std::string default_label(const IntegratorSpec& spec) {
  if (const Scheme* scheme = find_scheme(spec.scheme);
      scheme && scheme->family == "chin" && scheme->highest_order_index == 1)
    return spec.scheme;
  try {
    return spec.scheme + " " + Integrator::describe(spec).order.to_string();
  } catch (const InvalidArgument&) {
    return spec.scheme;
  }
}

}  // namespace

Study read_study(Checker& check, const json& study_value, HamiltonianForm form, double t_end) {
  Study study;
  const std::string path = "/study";
  const std::string what =
      "an object {\"integrators\": [...], \"steps\": [...] or \"dt\": [...], \"reference\": {\"q\", \"p\"}}";
  const KeyReader keys(check, study_value, path, study_keys(), what);
  if (!keys.is_object()) return study;
  std::string study_from;
  const std::size_t before = check.issue_count();
  const auto study_steps = read_steps_or_dt(check, study_value, path, t_end, false, study_from, "study.");
  const bool study_steps_invalid = check.issue_count() != before;

  const json* list = keys.value("integrators");
  if (list && (!list->is_array() || list->empty())) {
    check.issue(child(path, "integrators"), describe(*list),
                "a non-empty array of integrators, each {\"scheme\": ..., options, \"label\", \"steps\" or \"dt\"}");
    list = nullptr;
  }
  for (std::size_t i = 0; list && i < list->size(); ++i) {
    const std::string item = child(child(path, "integrators"), i);
    const json& entry = (*list)[i];
    if (!check.object(entry, item, "an integrator {\"scheme\": ..., options, \"label\", \"steps\" or \"dt\"}"))
      continue;
    StudyIntegrator integrator;
    integrator.spec = read_integrator_object(check, entry, item, form, study_integrator_keys().names());
    integrator.label = default_label(integrator.spec);
    if (const json* label = check.member(entry, item, "label", false, ""))
      if (auto text = check.string(*label, child(item, "label"), "a non-empty string naming the integrator"))
        integrator.label = *text;
    std::string from;
    if (entry.contains("steps") || entry.contains("dt")) {
      if (auto steps = read_steps_or_dt(check, entry, item, t_end, true, from, "integrator.")) {
        integrator.steps = std::move(*steps);
        integrator.steps_from = from;
      }
    } else if (study_steps) {
      integrator.steps = *study_steps;
      integrator.steps_from = study_from;
    } else if (!study_steps_invalid) {
      check.issue(child(item, "steps"), "nothing: neither this integrator nor /study gives steps or dt",
                  "\"steps\" or \"dt\" here, or in /study for every integrator");
    }
    for (const auto& other : study.integrators)
      if (other.label == integrator.label)
        check.issue(child(item, "label"), "\"" + integrator.label + "\", the label of an earlier integrator",
                    "a distinct label per integrator (add \"label\" to tell them apart)");
    study.integrators.push_back(std::move(integrator));
  }

  if (const json* run = keys.value("reference_run")) {
    const std::string run_path = keys.path("reference_run");
    if (study_value.contains("reference"))
      check.issue(run_path, "a reference run together with " + child(path, "reference"),
                  "either \"reference\" (the state at t_end) or \"reference_run\" (an integrator that computes it)");
    else if (check.object(*run, run_path, "an integrator {\"scheme\": ..., options, \"steps\": [N]}")) {
      StudyIntegrator reference;
      reference.spec = read_integrator_object(check, *run, run_path, form, study_integrator_keys().names());
      reference.label = "reference run";
      std::string from;
      if (auto steps = read_steps_or_dt(check, *run, run_path, t_end, true, from, "reference_run.")) {
        if (steps->size() == 1) {
          reference.steps = std::move(*steps);
          reference.steps_from = from;
          study.reference_run = std::move(reference);
        } else {
          check.issue(child(run_path, run->contains("steps") ? "steps" : "dt"),
                      std::to_string(steps->size()) + " step counts", "exactly one step count (or size)");
        }
      }
    }
  }
  if (const auto repeats = keys.integer("repeats")) study.repeats = static_cast<int>(*repeats);
  if (const json* reference = keys.value("reference")) {
    const std::string reference_path = keys.path("reference");
    if (check.object(*reference, reference_path, "the exact state at t_end {\"q\": [...], \"p\": [...]}")) {
      InitialStates state;
      read_state(check, *reference, reference_path, state, reference_path);
      study.reference_q = std::move(state.q);
      study.reference_p = std::move(state.p);
    }
  }
  return study;
}

}  // namespace nonsep::host::job_reader
