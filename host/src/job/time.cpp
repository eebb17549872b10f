// /time: a run's time grid {"dt", "t_end" or "steps"} and a study's {"t_end"}. Step counts from an end time come
// from steps_to_reach (nonsep/host/time_grid.hpp) through step_count, here and in a study's step sizes alike.
#include <cmath>

#include "nonsep/host/number_format.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

std::optional<std::uint64_t> step_count(Checker& check, double t_end, double dt, const std::string& path,
                                        const std::string& found) {
  const std::string limit = "at most " + std::to_string(max_steps) + " steps";
  // t_end / dt beyond the largest double (1e308 / 1e-308, 1 / 5e-324) is no count at all: over the limit too.
  const std::optional<double> rounded = steps_to_reach(t_end, dt);
  if (!rounded) {
    check.issue(path, found + ", whose t_end / dt is beyond the largest double", limit);
    return std::nullopt;
  }
  if (*rounded <= static_cast<double>(max_steps)) return static_cast<std::uint64_t>(*rounded);
  check.issue(path, found + ", which needs " + format_number(*rounded) + " steps", limit);
  return std::nullopt;
}

TimeGrid read_time(Checker& check, const KeyReader& document) {
  TimeGrid grid;
  const std::string what = "an object with \"dt\" and either \"t_end\" or \"steps\"";
  const json* time = document.value("time");
  if (!time) return grid;
  const KeyReader keys(check, *time, "/time", run_time_keys(), what);
  if (!keys.is_object()) return grid;
  // NaN marks a value that is missing or invalid (and already reported).
  const double dt = keys.number("dt").value_or(std::nan(""));
  if (!keys.pairs_hold()) return grid;  // exactly one of t_end and steps
  if (keys.given("t_end")) {
    const auto t_end = keys.number("t_end");
    if (!t_end || std::isnan(dt)) return grid;
    const std::string found = describe((*time)["t_end"]) + " with dt = " + format_number(dt);
    if (!(*t_end / dt > 0.0)) {
      check.issue("/time/t_end", found, "a non-zero end time of the same sign as dt (the run starts at t = 0)");
      return grid;
    }
    if (const auto steps = step_count(check, *t_end, dt, "/time/t_end", found))
      grid = TimeGrid::to_end(*t_end, dt, *steps);
    return grid;
  }
  const auto steps = keys.integer("steps");
  if (!steps || std::isnan(dt)) return grid;
  grid = TimeGrid::of_steps(static_cast<std::uint64_t>(*steps), dt);
  if (!std::isfinite(grid.t_end))
    check.issue("/time/steps", describe((*time)["steps"]) + " with dt = " + format_number(dt),
                "a number of steps whose end time steps * dt is finite");
  return grid;
}

TimeGrid read_study_time(Checker& check, const KeyReader& document) {
  TimeGrid grid;
  const std::string what = "an object {\"t_end\": T}: a study runs every integrator to T with its own step counts";
  const json* time = document.value("time");
  if (!time) return grid;
  // A run's time grid written in a study: said so, rather than as unknown keys.
  json rest = *time;
  if (rest.is_object())
    for (const char* key : {"dt", "steps"})
      if (rest.erase(key))
        check.issue(child("/time", key), describe((*time)[key]) + " in a study's /time",
                    "only \"t_end\" in a study's /time: the step sizes are each integrator's \"steps\" or \"dt\" in "
                    "/study/integrators, or /study's for every integrator");
  const KeyReader keys(check, rest, "/time", study_time_keys(), what);
  if (const auto t_end = keys.number("t_end")) grid.t_end = *t_end;
  return grid;
}

}  // namespace nonsep::host::job_reader
