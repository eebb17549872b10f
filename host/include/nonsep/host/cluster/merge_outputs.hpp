#pragma once
// Merging the outputs of work units (consecutive ranges of an ensemble's trajectories, each run on its own by some
// rank: distributed_run.hpp) into the files one process would have written, byte for byte.
//
// This works because every streamed file names each row by its (step, trajectory) or (trajectory) and is written in
// that order by one process (sample_writer.hpp, poincare_section.hpp, indicator_columns.hpp, trajectories.csv): the
// merged file is the unit files' rows in key order, with each unit's trajectory numbers shifted by its first
// trajectory. Rows with equal keys (two Poincare crossings in one step) come from one unit and keep their order.
#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

namespace nonsep::host {

struct UnitFile {
  std::filesystem::path path;
  std::size_t first_trajectory = 0;  // added to the file's `trajectory` column
};

// Writes `output` (atomically) from `parts`, which must share one header, merged by the integer columns `keys`
// (named in the header; e.g. {"step", "trajectory"}), compared in that order, then by part. Cells may be quoted
// CSV text with commas and line breaks; the key and trajectory columns must come before any quoted cell. Throws
// OutputError naming the file that cannot be read or does not fit.
void merge_csv(std::span<const UnitFile> parts, const std::filesystem::path& output, std::span<const std::string> keys);

// frequency_signals.npy of the whole run (observers/sampled_indicator.hpp) from the units' (in trajectory order): their
// arrays, which must agree in signals and samples, one after the other. Written atomically. Throws OutputError
// naming the unit file that cannot be read or does not fit.
void merge_signals(std::span<const UnitFile> parts, const std::filesystem::path& output);

// summary.json of the whole run from the units' summaries (in trajectory order; `first_trajectories` as above):
// the first unit's, with what depends on the ensemble recomputed: status (the first of interrupted, failed,
// diverged, inaccurate, completed that a unit has), error, counts and evaluations (sums), steps completed (the
// largest), the largest energy error (the first unit's largest that no later unit exceeds, as one process finds it),
// the scheme's figures (the largest: Tao's copy distance), Poincare crossings and analysed frequency maps (sums), the
// number of trajectories and states, the output folder, and wall_seconds (the run's, passed in).
nlohmann::ordered_json merge_summaries(std::span<const nlohmann::ordered_json> units,
                                       std::span<const std::size_t> first_trajectories, std::size_t trajectories,
                                       const std::filesystem::path& directory, double wall_seconds);

}  // namespace nonsep::host
