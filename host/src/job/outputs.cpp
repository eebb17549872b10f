// /output (where results go and how often), /analysis (per-trajectory analyses of a run) and /checkpoint (when a
// run saves checkpoint.json).
#include <limits>

#include "sections.hpp"

namespace nonsep::host::job_reader {

void read_output(Checker& check, const json& document, Job& job) {
  std::filesystem::path output = job.file.stem().string() + ".out";
  if (const json* section = check.member(document, "", "output", false, "");
      section && check.object(*section, "/output", "an object {\"directory\": ..., \"every\": ...}")) {
    check.known_keys(*section, "/output", {"directory", "every", "energy_every"});
    if (const json* directory = check.member(*section, "/output", "directory", false, ""))
      if (auto text = check.path_string(*directory, "/output/directory",
                                        "a folder name or path, relative to the job file's folder"))
        output = *text;
    if (const json* every = check.member(*section, "/output", "every", false, ""))
      if (auto stride = check.integer(*every, "/output/every", 0, std::numeric_limits<std::int64_t>::max(),
                                      "an integer >= 0: write every n-th step to trajectory.csv (0: no trajectory)"))
        job.every = static_cast<std::uint64_t>(*stride);
    if (const json* energy_every = check.member(*section, "/output", "energy_every", false, ""))
      if (auto stride = check.integer(*energy_every, "/output/energy_every", 0,
                                      std::numeric_limits<std::int64_t>::max(),
                                      "an integer >= 0: also evaluate H every n-th step (0: only at the written "
                                      "samples, the start and the end)"))
        job.energy_every = static_cast<std::uint64_t>(*stride);
  }
  job.output_directory = output.is_absolute() ? output : job.directory / output;
}

Analysis read_analysis(Checker& check, const json& value, std::size_t dimension) {
  Analysis analysis;
  const std::string path = "/analysis";
  if (!check.object(value, path,
                    "an object {\"closest_return_after\": t, \"max_relative_energy_error\": e, \"poincare\": {...}, "
                    "\"lyapunov\": {...}, \"megno\": true}"))
    return analysis;
  check.known_keys(value, path,
                   {"closest_return_after", "max_relative_energy_error", "poincare", "lyapunov", "megno"});
  read_dynamics(check, value, dimension, analysis);
  if (const json* after = check.member(value, path, "closest_return_after", false, ""))
    analysis.closest_return_after = check.finite_number(
        *after, child(path, "closest_return_after"),
        "a finite time: from then on the smallest phase-space distance to the initial state is tracked");
  if (const json* bound = check.member(value, path, "max_relative_energy_error", false, ""))
    analysis.max_relative_energy_error =
        check.positive_number(*bound, child(path, "max_relative_energy_error"),
                              "a finite number > 0: a trajectory whose |H - H0| / |H0| exceeds it stops with status "
                              "\"inaccurate\"");
  return analysis;
}

CheckpointPolicy read_checkpoint(Checker& check, const json& value) {
  CheckpointPolicy checkpoint;
  const std::string path = "/checkpoint";
  if (!check.object(value, path, "an object {\"every_steps\": n, \"every_seconds\": s}")) return checkpoint;
  check.known_keys(value, path, {"every_steps", "every_seconds"});
  if (const json* steps = check.member(value, path, "every_steps", false, ""))
    if (auto n = check.integer(*steps, child(path, "every_steps"), 0, static_cast<std::int64_t>(max_steps),
                               "an integer from 0 to " + std::to_string(max_steps) +
                                   ": save a checkpoint every n steps (0: not by steps)"))
      checkpoint.every_steps = static_cast<std::uint64_t>(*n);
  if (const json* seconds = check.member(value, path, "every_seconds", false, "")) {
    const std::string what = "a finite number >= 0: save a checkpoint every s seconds of wall time (0: not by time)";
    if (auto s = check.finite_number(*seconds, child(path, "every_seconds"), what)) {
      if (*s < 0.0)
        check.issue(child(path, "every_seconds"), describe(*seconds), what);
      else
        checkpoint.every_seconds = *s;
    }
  }
  return checkpoint;
}

}  // namespace nonsep::host::job_reader
