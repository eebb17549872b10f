#pragma once
// The one list of indicators a job's /analysis can ask for (nonsep/core/analysis/indicator.hpp), in the order of
// their columns in trajectories.csv and lyapunov.csv: frequency map analysis (which needs samples of the state), then
// the chaos indicators of the tangent map; each with its key's rule (the schema, docs/job-file.md and the known keys
// of /analysis take it from here) and its reading. Adding an indicator is its class in
// core/include/nonsep/core/analysis/ and its entry here.
#include <cstddef>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "job_keys.hpp"
#include "nonsep/core/analysis/indicator.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/json/checker.hpp"

namespace nonsep::host::job_reader {

struct IndicatorEntry {
  KeyRule rule;
  // Reads the key's value at `path` (present in the job, and of the rule's type and range: /analysis's KeyReader
  // checked it) for initial states of `dimension` (0 when unknown): the
  // indicator it asks for, or nothing (false, or an issue was reported). May set what the indicator shares with
  // the run (analysis.lyapunov: the tangent vectors' renormalisation and the series).
  std::shared_ptr<const Indicator> (*read)(Checker& check, const nlohmann::json& value, const std::string& path,
                                           std::size_t dimension, Analysis& analysis);
};

const std::vector<IndicatorEntry>& indicator_entries();

}  // namespace nonsep::host::job_reader
