// /output (where results go and how often), /analysis (per-trajectory analyses of a run) and /checkpoint (when a
// run saves checkpoint.json).
#include "nonsep/host/platform/build_features.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

namespace {

// A study writes convergence.csv only; refusing "hdf5" there says so instead of ignoring what was asked. A build
// without HDF5 refuses it here, before any plugin is loaded, rather than at the end of a run.
OutputFormat read_format(Checker& check, const json& value, bool study) {
  const std::string text = value.is_string() ? value.get<std::string>() : "";
  if (text == "csv") return OutputFormat::csv;
  if (text != "hdf5") {
    check.issue("/output/format", describe(value), "\"csv\" or \"hdf5\"");
  } else if (study) {
    check.issue("/output/format", "\"hdf5\" together with /study",
                "\"csv\": a study writes convergence.csv; results.h5 is written by single runs");
  } else if (!built_with_hdf5()) {
    check.issue("/output/format", "\"hdf5\", but this build of nonsep has no HDF5 (`nonsep --version`)",
                "\"csv\", or a build configured with -DNONSEP_WITH_HDF5=ON and the HDF5 library installed");
  }
  return OutputFormat::hdf5;
}

}  // namespace

void read_flag(Checker& check, const json& value, const std::string& path, const std::string& key,
               const std::string& meaning, bool& flag) {
  const json* member = check.member(value, path, key, false, "");
  if (!member) return;
  if (member->is_boolean())
    flag = member->get<bool>();
  else
    check.issue(child(path, key), describe(*member), "true or false: " + meaning);
}

void read_output(Checker& check, const json& document, Job& job) {
  SingleRun study_strides;  // a study's /output/every and /output/energy_every are checked but not used
  SingleRun& run = job.is_study() ? study_strides : std::get<SingleRun>(job.plan);
  std::filesystem::path output = job.file.stem().string() + ".out";
  if (const json* section = check.member(document, "", "output", false, "");
      section && check.object(*section, "/output", "an object {\"directory\": ..., \"every\": ...}")) {
    const KeyTable& keys = output_keys();
    check.known_keys(*section, "/output", keys.names());
    if (const json* directory = check.member(*section, "/output", "directory", false, ""))
      if (auto text = check.path_string(*directory, "/output/directory",
                                        "a folder name or path, relative to the job file's folder"))
        output = *text;
    if (const json* every = check.member(*section, "/output", "every", false, ""))
      if (auto stride = check.integer(*every, "/output/every", keys["every"].minimum, keys["every"].maximum,
                                      "an integer >= 0: write every n-th step to trajectory.csv (0: no trajectory)"))
        run.every = static_cast<std::uint64_t>(*stride);
    if (const json* energy_every = check.member(*section, "/output", "energy_every", false, ""))
      if (auto stride = check.integer(*energy_every, "/output/energy_every", keys["energy_every"].minimum,
                                      keys["energy_every"].maximum,
                                      "an integer >= 0: also evaluate H every n-th step (0: only at the written "
                                      "samples, the start and the end)"))
        run.energy_every = static_cast<std::uint64_t>(*stride);
    if (const json* format = check.member(*section, "/output", "format", false, ""))
      run.format = read_format(check, *format, job.is_study());
  }
  job.output_directory = output.is_absolute() ? output : job.directory / output;
}

Analysis read_analysis(Checker& check, const json& value, std::size_t dimension) {
  Analysis analysis;
  const std::string path = "/analysis";
  if (!check.object(value, path,
                    "an object {\"closest_return_after\": t, \"max_relative_energy_error\": e, \"poincare\": {...}, "
                    "\"lyapunov\": {...}, \"megno\": true, \"sali\": true, \"gali\": k, \"error_estimate\": true}"))
    return analysis;
  check.known_keys(value, path, analysis_keys().names());
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
  read_flag(check, value, path, "error_estimate",
            "estimate each trajectory's global error by a second run with half the step", analysis.error_estimate);
  return analysis;
}

CheckpointPolicy read_checkpoint(Checker& check, const json& value) {
  CheckpointPolicy checkpoint;
  const std::string path = "/checkpoint";
  if (!check.object(value, path, "an object {\"every_steps\": n, \"every_seconds\": s}")) return checkpoint;
  const KeyTable& keys = checkpoint_keys();
  check.known_keys(value, path, keys.names());
  const KeyRule& every_steps = keys["every_steps"];
  if (const json* steps = check.member(value, path, "every_steps", false, ""))
    if (auto n = check.integer(*steps, child(path, "every_steps"), every_steps.minimum, every_steps.maximum,
                               "an integer from " + std::to_string(every_steps.minimum) + " to " +
                                   std::to_string(every_steps.maximum) +
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
