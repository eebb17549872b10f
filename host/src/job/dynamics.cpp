// /analysis/poincare, /analysis/frequencies and the chaos indicators (/analysis/lyapunov, /megno, /sali, /gali, /fli,
// /ofli: the list of indicators.cpp): the dynamics diagnostics of a run (docs/dynamics.md). Whether the plugin has the
// Hessians the tangent map needs is checked when the job is loaded (load_job.cpp), where the plugin is known.
#include <algorithm>
#include <limits>

#include "indicators.hpp"
#include "job_keys.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

namespace {

// "q0", "p12": the index into (q, p) of n + n numbers, or nothing.
std::optional<std::size_t> component_index(const std::string& name, std::size_t dimension) {
  if (name.size() < 2 || (name[0] != 'q' && name[0] != 'p')) return std::nullopt;
  std::size_t index = 0;
  for (std::size_t i = 1; i < name.size(); ++i) {
    if (name[i] < '0' || name[i] > '9' || (i == 1 && name[i] == '0' && name.size() > 2) || index > 1000000)
      return std::nullopt;
    index = index * 10 + static_cast<std::size_t>(name[i] - '0');
  }
  if (index >= dimension) return std::nullopt;
  return (name[0] == 'q' ? 0 : dimension) + index;
}

std::optional<PoincareSection> read_poincare(Checker& check, const json& value, std::size_t dimension) {
  const std::string path = "/analysis/poincare";
  if (!check.object(value, path,
                    "an object {\"component\": \"q0\" (or \"normal\": [2n numbers]), \"value\": c, \"direction\": "
                    "\"+\", \"max_crossings\": N}"))
    return std::nullopt;
  check.known_keys(value, path, poincare_keys().names());
  const std::size_t issues = check.issue_count();
  PoincareSection section;
  const bool has_component = value.contains("component"), has_normal = value.contains("normal");
  const std::string components = dimension > 0 ? "\"q0\" .. \"q" + std::to_string(dimension - 1) +
                                                     "\" or \"p0\" .. \"p" + std::to_string(dimension - 1) + "\""
                                               : "\"q<i>\" or \"p<i>\"";
  if (has_component == has_normal) {
    check.issue(path, has_component ? "both \"component\" and \"normal\"" : "neither \"component\" nor \"normal\"",
                "exactly one of \"component\" (" + components + ") and \"normal\" (2n numbers, n for q then n for p)");
  } else if (has_component) {
    const json& component = value["component"];
    const auto index = component.is_string() ? component_index(component.get<std::string>(), dimension) : std::nullopt;
    if (!index) {
      check.issue(child(path, "component"), describe(component), components + ", a component of the state");
    } else {
      section.normal.assign(2 * dimension, 0.0);
      section.normal[*index] = 1.0;
    }
  } else if (auto normal = check.vector(value["normal"], child(path, "normal"))) {
    double squared = 0.0;
    for (double x : *normal) squared += x * x;
    if (normal->size() != 2 * dimension && dimension > 0)
      check.issue(child(path, "normal"), std::to_string(normal->size()) + " numbers",
                  std::to_string(2 * dimension) + " numbers (2n: n for q, then n for p)");
    else if (!(squared > 0.0) || !std::isfinite(squared))
      check.issue(child(path, "normal"), describe(value["normal"]), "a normal vector that is not zero");
    else
      section.normal = std::move(*normal);
  }
  if (value.contains("value") && value.contains("offset"))
    check.issue(path, "both \"value\" and \"offset\"", "one of them: the plane is normal . (q, p) = value");
  for (const char* key : {"value", "offset"})
    if (const json* c = check.member(value, path, key, false, ""))
      if (auto number = check.finite_number(*c, child(path, key),
                                            "a finite number: the plane is normal . (q, p) = "
                                            "value (default 0)"))
        section.offset = *number;
  if (const json* direction = check.member(value, path, "direction", false, "")) {
    const std::string text = direction->is_string() ? direction->get<std::string>() : "";
    if (text == "+")
      section.direction = CrossingDirection::up;
    else if (text == "-")
      section.direction = CrossingDirection::down;
    else if (text == "both")
      section.direction = CrossingDirection::both;
    else
      check.issue(child(path, "direction"), describe(*direction),
                  "\"+\" (normal . (q, p) - value goes from < 0 to >= 0; the default), \"-\" or \"both\"");
  }
  if (const json* cap = check.member(value, path, "max_crossings", false, ""))
    if (auto n = check.integer(*cap, child(path, "max_crossings"), 1, std::numeric_limits<std::int64_t>::max(),
                               "an integer >= 1: a trajectory stops (status \"completed\", with a message) at the "
                               "step of its N-th crossing"))
      section.max_crossings = static_cast<std::uint64_t>(*n);
  if (check.issue_count() != issues) return std::nullopt;
  return section;
}

std::optional<FrequencyMap> read_frequencies(Checker& check, const json& value, std::size_t dimension) {
  const std::string path = "/analysis/frequencies";
  if (!check.object(value, path, "an object {\"every\": k, \"signals\": [degrees of freedom], \"spectra\": m}"))
    return std::nullopt;
  const KeyTable& keys = frequencies_keys();
  check.known_keys(value, path, keys.names());
  const std::size_t issues = check.issue_count();
  FrequencyMap frequencies;
  if (const json* every = check.member(value, path, "every", false, ""))
    if (auto n = check.integer(*every, child(path, "every"), keys["every"].minimum, keys["every"].maximum,
                               "an integer >= 1: steps between samples (default 1)"))
      frequencies.every = static_cast<std::uint64_t>(*n);
  if (const json* spectra = check.member(value, path, "spectra", false, ""))
    if (auto n = check.integer(*spectra, child(path, "spectra"), keys["spectra"].minimum, keys["spectra"].maximum,
                               "an integer from 0 to 1000: terms per signal in frequency_spectra.csv (0: no file)"))
      frequencies.spectra = static_cast<std::size_t>(*n);
  const std::string degrees = dimension > 0 ? "from 0 to " + std::to_string(dimension - 1) : "below the dimension";
  if (const json* signals = check.member(value, path, "signals", false, "")) {
    const std::string what =
        "a non-empty list of distinct degrees of freedom k (" + degrees + "): the signals q_k + i p_k, numbered from 0";
    if (!signals->is_array() || signals->empty()) check.issue(child(path, "signals"), describe(*signals), what);
    for (std::size_t i = 0; signals->is_array() && i < signals->size(); ++i) {
      const std::string at = child(path, "signals") + "/" + std::to_string(i);
      const auto k = check.integer((*signals)[i], at, 0, std::numeric_limits<std::int64_t>::max(), what);
      if (!k) continue;
      const auto degree = static_cast<std::size_t>(*k);
      if (dimension > 0 && degree >= dimension)
        check.issue(at, std::to_string(degree), "a degree of freedom " + degrees + " (numbered from 0)");
      else if (std::find(frequencies.signals.begin(), frequencies.signals.end(), degree) != frequencies.signals.end())
        check.issue(at, std::to_string(degree) + " again", "each degree of freedom once");
      else
        frequencies.signals.push_back(degree);
    }
  } else {
    for (std::size_t k = 0; k < dimension; ++k) frequencies.signals.push_back(k);
  }
  if (check.issue_count() != issues) return std::nullopt;
  return frequencies;
}

}  // namespace

void read_dynamics(Checker& check, const json& value, std::size_t dimension, Analysis& analysis) {
  const std::string path = "/analysis";
  if (const json* poincare = check.member(value, path, "poincare", false, ""))
    analysis.poincare = read_poincare(check, *poincare, dimension);
  if (const json* frequencies = check.member(value, path, "frequencies", false, ""))
    analysis.frequencies = read_frequencies(check, *frequencies, dimension);
  for (const IndicatorEntry& entry : indicator_entries())
    if (const json* member = check.member(value, path, entry.rule.name, false, ""))
      if (auto indicator = entry.read(check, *member, child(path, entry.rule.name), dimension, analysis))
        analysis.indicators.push_back(std::move(indicator));
}

}  // namespace nonsep::host::job_reader
