// The one list of chaos indicators: which of nonsep/core/analysis's indicators a job's /analysis asks for, in the
// order of their columns in trajectories.csv and lyapunov.csv. The driver, the columns and series, the checkpoint and
// summary.json iterate over it.
#include "nonsep/core/analysis/alignment_indices.hpp"
#include "nonsep/core/analysis/fast_lyapunov_indicator.hpp"
#include "nonsep/core/analysis/megno.hpp"
#include "nonsep/host/job.hpp"

namespace nonsep::host {

IndicatorList Analysis::indicators() const {
  IndicatorList list;
  if (lyapunov) list.push_back(std::make_shared<LyapunovIndicator>(lyapunov->vectors));
  if (megno) list.push_back(std::make_shared<MegnoIndicator>());
  if (sali) list.push_back(std::make_shared<AlignmentIndicator>(AlignmentIndicator::sali()));
  if (gali > 0) list.push_back(std::make_shared<AlignmentIndicator>(AlignmentIndicator::gali(gali)));
  if (fli) list.push_back(std::make_shared<FastLyapunovIndicator>());
  return list;
}

std::size_t Analysis::tangent_vectors() const {
  std::size_t k = 0;
  for (const auto& indicator : indicators()) k = std::max(k, indicator->needs().tangent_vectors);
  return k;
}

std::string Analysis::tangent_key() const {
  const IndicatorList list = indicators();
  return list.empty() ? "" : "/analysis/" + list.front()->name();
}

}  // namespace nonsep::host
