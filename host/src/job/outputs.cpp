// /output (where results go and how often), /analysis (per-trajectory analyses of a run) and /checkpoint (when a
// run saves checkpoint.json).
#include "key_reader.hpp"
#include "nonsep/host/platform/build_features.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

namespace {

// /output/format, one of the table's choices. A study writes convergence.csv only; refusing "hdf5" there says so
// instead of ignoring what was asked. A build without HDF5 refuses it here, before any plugin is loaded, rather than
// at the end of a run.
OutputFormat read_format(Checker& check, const std::string& format, bool study) {
  if (format == "csv") return OutputFormat::csv;
  if (study) {
    check.issue("/output/format", "\"hdf5\" together with /study",
                "\"csv\": a study writes convergence.csv; results.h5 is written by single runs");
  } else if (!built_with_hdf5()) {
    check.issue("/output/format", "\"hdf5\", but this build of nonsep has no HDF5 (`nonsep --version`)",
                "\"csv\", or a build configured with -DNONSEP_WITH_HDF5=ON and the HDF5 library installed");
  }
  return OutputFormat::hdf5;
}

}  // namespace

void read_output(Checker& check, const KeyReader& document, Job& job) {
  SingleRun study_strides;  // a study has no strides: refused below, after the table has checked them
  SingleRun& run = job.is_study() ? study_strides : std::get<SingleRun>(job.plan);
  std::filesystem::path output = job.file.stem().string() + ".out";
  if (const json* section = document.value("output")) {
    const KeyReader keys(check, *section, "/output", output_keys(), "an object {\"directory\": ..., \"every\": ...}");
    if (job.is_study())  // a study writes convergence.csv only: a stride would be taken and do nothing
      for (const char* key : {"every", "energy_every"})
        if (keys.value(key))  // given and of the table's type
          check.issue(child("/output", key), describe((*section)[key]) + " together with /study",
                      "no stride in a study: it writes convergence.csv (one row per integrator and step count) and no "
                      "samples; its energy error is measured at every step");
    if (const auto directory = keys.string("directory")) output = *directory;
    if (const auto every = keys.integer("every")) run.every = static_cast<std::uint64_t>(*every);
    if (const auto every = keys.integer("energy_every")) run.energy_every = static_cast<std::uint64_t>(*every);
    if (const auto format = keys.string("format")) run.format = read_format(check, *format, job.is_study());
  }
  job.output_directory = output.is_absolute() ? output : job.directory / output;
}

Analysis read_analysis(Checker& check, const json& value, std::size_t dimension) {
  Analysis analysis;
  const KeyReader keys(check, value, "/analysis", analysis_keys(),
                       "an object {\"closest_return_after\": t, \"max_relative_energy_error\": e, \"poincare\": "
                       "{...}, \"lyapunov\": {...}, \"megno\": true, \"sali\": true, \"gali\": k, \"error_estimate\": "
                       "true}");
  if (!keys.is_object()) return analysis;
  read_dynamics(check, keys, dimension, analysis);
  analysis.closest_return_after = keys.number("closest_return_after");
  analysis.max_relative_energy_error = keys.number("max_relative_energy_error");
  analysis.error_estimate = keys.boolean("error_estimate").value_or(analysis.error_estimate);
  return analysis;
}

CheckpointPolicy read_checkpoint(Checker& check, const json& value) {
  CheckpointPolicy checkpoint;
  const KeyReader keys(check, value, "/checkpoint", checkpoint_keys(),
                       "an object {\"every_steps\": n, \"every_seconds\": s}");
  if (const auto steps = keys.integer("every_steps")) checkpoint.every_steps = static_cast<std::uint64_t>(*steps);
  checkpoint.every_seconds = keys.number("every_seconds").value_or(checkpoint.every_seconds);
  return checkpoint;
}

}  // namespace nonsep::host::job_reader
