#pragma once
// summary.json's text. The few header keys (status, job, model, integrator, time, energy, output, counts,
// evaluations, wall_seconds) are an nlohmann::ordered_json; the per-trajectory entries of /trajectories are written
// as text straight from the run's records and streamed to the file. Building a json value for every entry (some
// thirty small allocations, then dumping and freeing them) cost about 48,000 instructions per trajectory, more than
// 4000 basic steps of paper1d's block stepping do once amortized per step (callgrind, 1024 trajectories;
// docs/performance.md, figure 2); the text writer takes about 12,000, and its memory does not grow with the
// ensemble.
//
// The layout is exactly nlohmann's dump(2) of the whole document: numbers are shortest round-trip decimal
// (std::to_chars), with ".0" on integral values as nlohmann writes doubles; a non-finite number is null; strings
// are escaped by nlohmann, invalid UTF-8 replaced by U+FFFD.
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nonsep/host/checkpoint.hpp"

namespace nonsep::host {

// What every entry of /trajectories is written from.
struct TrajectoryEntries {
  std::span<const TrajectoryRecord> records;  // one per trajectory, in job order (the entry's "index")
  std::span<const double> initial_q, initial_p;  // the job's initial states, state-major
  std::size_t dimension = 0;
  bool closest_return = false;  // the job asks for /analysis/closest_return_after: every entry has "closest_return"
};

// The text of summary.json: `header` (which holds "trajectories": null where the entries go) with the entries in
// that place, ending in a newline. Throws std::logic_error when the header has no such member.
// /trajectories is laid out as nlohmann dumps a top-level array: entries indented by 4 spaces, their keys by 6.
// Entry keys, in order: index, status, initial {q, p}, final {t, step, q, p}, energy {initial, final,
// relative_error_final, relative_error_max_abs}, diverged {step, t, variable} (status "diverged" only), error (when
// there is one), closest_return {distance, t, step} or null (when asked for). A large ensemble's entries are
// formatted on up to `threads` threads, 256 consecutive entries each at a time (the text is the same for any
// number).
std::string summary_json_text(const nlohmann::ordered_json& header, const TrajectoryEntries& entries,
                              unsigned threads = 1);

// Writes that text to `path` atomically (AtomicFile), streamed: memory stays at a few buffers of 256 entries
// however many trajectories there are. Throws OutputError.
void write_summary_json(const std::filesystem::path& path, const nlohmann::ordered_json& header,
                        const TrajectoryEntries& entries, unsigned threads = 1);

// Appends `value` as a JSON number the way nlohmann::json dumps a double ("2.0", "0.1", "1e-05"), or null when it
// is not finite.
void append_json_number(std::string& out, double value);

}  // namespace nonsep::host
