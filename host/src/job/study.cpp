// /study: a convergence study's integrators, their step counts (per integrator or shared; counts, or step sizes
// turned into counts by step_count), and the optional exact reference state at t_end.
#include <algorithm>

#include "nonsep/core/base/error.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

namespace {

// The step counts of `keys`' "steps" (counts, distinct by the table) or "dt" (step sizes, each turned into a count
// over `t_end`; 0 when the end time is invalid: the sizes are then only checked), sorted; nothing when neither is
// given or a value is refused. The table allows at most one of them. `from` is set to `from_prefix` + the key used.
std::optional<std::vector<std::uint64_t>> read_steps_or_dt(Checker& check, const KeyReader& keys, double t_end,
                                                           std::string& from, const std::string& from_prefix) {
  if (keys.given("steps") && keys.given("dt")) return std::nullopt;  // the table's pair says so
  std::vector<std::uint64_t> result;
  if (const auto counts = keys.integers("steps")) {
    for (const std::int64_t n : *counts) result.push_back(static_cast<std::uint64_t>(n));
    from = from_prefix + "steps";
  } else if (keys.given("dt")) {
    // Each size the table accepts is held to t_end's sign and turned into a count, whether or not another was
    // refused (every problem at once).
    from = from_prefix + "dt";
    bool ok = keys.value("dt") != nullptr;
    for (const auto& [i, item] : keys.accepted_items("dt")) {
      const std::string at = child(keys.path("dt"), i), found = describe(*item);
      const double dt = item->get<double>();
      if (t_end != 0.0 && !(t_end / dt > 0.0)) {
        check.issue(at, found, "a non-zero step size of the same sign as /time/t_end");
        ok = false;
      } else if (t_end != 0.0) {
        const auto steps = step_count(check, t_end, dt, at, found + " to /time/t_end");
        if (steps) result.push_back(*steps);
        ok = ok && steps.has_value();
      }
    }
    if (!ok) return std::nullopt;
  } else {
    return std::nullopt;
  }
  std::sort(result.begin(), result.end());
  if (std::adjacent_find(result.begin(), result.end()) != result.end()) {  // sizes only: counts are distinct
    check.issue(keys.path("dt"), describe(keys.object()["dt"]) + ", which gives the same step count twice",
                "distinct step sizes (each gives ceil(t_end / dt) steps)");
    return std::nullopt;
  }
  return result;
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
  const auto study_steps = read_steps_or_dt(check, keys, t_end, study_from, "study.");
  const bool study_gives_steps = keys.given("steps") || keys.given("dt");  // valid or not (then reported)

  const json* list = keys.value("integrators");
  if (list && (!list->is_array() || list->empty())) {
    check.issue(child(path, "integrators"), describe(*list),
                "a non-empty array of integrators, each {\"scheme\": ..., options, \"label\", \"steps\" or \"dt\"}");
    list = nullptr;
  }
  for (std::size_t i = 0; list && i < list->size(); ++i) {
    const std::string item = child(child(path, "integrators"), i);
    const IntegratorReader reader(check, (*list)[i], item, form, &study_integrator_keys(),
                                  "an integrator {\"scheme\": ..., options, \"label\", \"steps\" or \"dt\"}");
    const KeyReader& entry = reader.keys();
    // An entry that is no object or names no scheme of the catalogue has its issue; its label and steps would only
    // repeat it (an unknown scheme's spec is no scheme's: two of them would share a default label).
    if (!entry.is_object() || !reader.scheme_known()) continue;
    StudyIntegrator integrator;
    integrator.spec = reader.spec();
    integrator.label = entry.string("label").value_or(default_label(integrator.spec));
    std::string from;
    if (entry.given("steps") || entry.given("dt")) {
      if (auto steps = read_steps_or_dt(check, entry, t_end, from, "integrator.")) {
        integrator.steps = std::move(*steps);
        integrator.steps_from = from;
      }
    } else if (study_steps) {
      integrator.steps = *study_steps;
      integrator.steps_from = study_from;
    } else if (!study_gives_steps) {
      check.issue(child(item, "steps"), "nothing: neither this integrator nor /study gives steps or dt",
                  "\"steps\" or \"dt\" here, or in /study for every integrator");
    }
    for (const auto& other : study.integrators)
      if (other.label == integrator.label)
        check.issue(child(item, "label"), "\"" + integrator.label + "\", the label of an earlier integrator",
                    "a distinct label per integrator (add \"label\" to tell them apart)");
    study.integrators.push_back(std::move(integrator));
  }

  // Not together with "reference" (the table's pair).
  if (const json* run = keys.value("reference_run"); run && !keys.given("reference")) {
    const std::string run_path = keys.path("reference_run");
    const IntegratorReader reader(check, *run, run_path, form, &study_integrator_keys(),
                                  "an integrator {\"scheme\": ..., options, \"steps\": [N]}");
    const KeyReader& entry = reader.keys();
    std::string from;
    if (entry.is_object() && !entry.given("steps") && !entry.given("dt"))
      check.issue(entry.path("steps"), "nothing (neither \"steps\" nor \"dt\" is given)",
                  "\"steps\": [step counts over /time/t_end] or \"dt\": [step sizes]");
    else if (auto steps = read_steps_or_dt(check, entry, t_end, from, "reference_run.")) {
      if (steps->size() == 1) {
        StudyIntegrator reference;
        reference.spec = reader.spec();
        reference.label = "reference run";
        reference.steps = std::move(*steps);
        reference.steps_from = from;
        study.reference_run = std::move(reference);
      } else {
        check.issue(entry.path(entry.given("steps") ? "steps" : "dt"), std::to_string(steps->size()) + " step counts",
                    "exactly one step count (or size)");
      }
    }
  }
  if (const auto repeats = keys.integer("repeats")) study.repeats = static_cast<int>(*repeats);
  if (const json* reference = keys.value("reference")) {
    const std::string reference_path = keys.path("reference");
    InitialStates state;
    read_state(check, *reference, reference_path, state, reference_path,
               "the exact state at t_end {\"q\": [...], \"p\": [...]}");
    study.reference_q = std::move(state.q);
    study.reference_p = std::move(state.p);
  }
  return study;
}

}  // namespace nonsep::host::job_reader
