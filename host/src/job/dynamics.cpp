// /analysis/poincare and the indicators (/analysis/frequencies, /lyapunov, /megno, /sali, /gali, /fli, /ofli: the list
// of indicators.cpp): the dynamics diagnostics of a run (docs/dynamics.md). Whether the plugin has the
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
  const std::size_t issues = check.issue_count();
  const KeyReader keys(check, value, path, poincare_keys(),
                       "an object {\"component\": \"q0\" (or \"normal\": [2n numbers]), \"value\": c, \"direction\": "
                       "\"+\", \"max_crossings\": N}");
  if (!keys.is_object()) return std::nullopt;
  PoincareSection section;
  const std::string components = dimension > 0 ? "\"q0\" .. \"q" + std::to_string(dimension - 1) +
                                                     "\" or \"p0\" .. \"p" + std::to_string(dimension - 1) + "\""
                                               : "\"q<i>\" or \"p<i>\"";
  // Exactly one of component and normal (the table's pair says so when not).
  const bool one = keys.given("component") != keys.given("normal");
  if (const auto component = keys.string("component"); component && one) {
    if (const auto index = component_index(*component, dimension)) {
      section.normal.assign(2 * dimension, 0.0);
      section.normal[*index] = 1.0;
    } else {
      check.issue(keys.path("component"), describe(value["component"]), components + ", a component of the state");
    }
  } else if (auto normal = keys.numbers("normal"); normal && one) {
    double squared = 0.0;
    for (double x : *normal) squared += x * x;
    if (normal->size() != 2 * dimension && dimension > 0)
      check.issue(keys.path("normal"), std::to_string(normal->size()) + " numbers",
                  std::to_string(2 * dimension) + " numbers (2n: n for q, then n for p)");
    else if (!(squared > 0.0) || !std::isfinite(squared))
      check.issue(keys.path("normal"), describe(value["normal"]), "a normal vector that is not zero");
    else
      section.normal = std::move(*normal);
  }
  for (const char* key : {"value", "offset"})
    if (const auto offset = keys.number(key)) section.offset = *offset;
  if (const auto direction = keys.string("direction"))
    section.direction = *direction == "+"   ? CrossingDirection::up
                        : *direction == "-" ? CrossingDirection::down
                                            : CrossingDirection::both;
  if (const auto n = keys.integer("max_crossings")) section.max_crossings = static_cast<std::uint64_t>(*n);
  if (check.issue_count() != issues) return std::nullopt;
  return section;
}

}  // namespace

void read_dynamics(Checker& check, const KeyReader& analysis_keys, std::size_t dimension, Analysis& analysis) {
  if (const json* poincare = analysis_keys.value("poincare"))
    analysis.poincare = read_poincare(check, *poincare, dimension);
  for (const IndicatorEntry& entry : indicator_entries())
    if (const json* member = analysis_keys.value(entry.rule.name))
      if (auto indicator = entry.read(check, *member, analysis_keys.path(entry.rule.name), dimension, analysis))
        analysis.indicators.push_back(std::move(indicator));
}

}  // namespace nonsep::host::job_reader
