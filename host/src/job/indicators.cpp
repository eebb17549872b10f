// The one list of a job's indicators (indicators.hpp): the frequency map, then the chaos indicators of the tangent
// map; each key's rule and reading.
#include "indicators.hpp"

#include <algorithm>
#include <limits>

#include "nonsep/core/analysis/alignment_indices.hpp"
#include "nonsep/core/analysis/fast_lyapunov_indicator.hpp"
#include "nonsep/core/analysis/frequency_map_indicator.hpp"
#include "nonsep/core/analysis/lyapunov_exponents.hpp"
#include "nonsep/core/analysis/megno.hpp"
#include "nonsep/core/analysis/orthogonal_fast_lyapunov_indicator.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

namespace {

using json = nlohmann::json;

// The most tangent vectors a trajectory can have: 2n, at most LyapunovRecord::max_exponents (2 when n is unknown).
std::size_t most_tangent_vectors(std::size_t dimension) {
  return std::min<std::size_t>(LyapunovRecord::max_exponents, dimension > 0 ? 2 * dimension : 2);
}

// Refuses a number of tangent vectors above the most the states' dimension allows (the table allows up to 32). With
// the dimension unknown (the initial states have a problem of their own, reported) there is nothing to hold k to.
bool within_dimension(Checker& check, std::int64_t k, std::int64_t least, std::size_t dimension, const std::string& at,
                      const std::string& meaning) {
  const std::size_t most = most_tangent_vectors(dimension);
  if (dimension == 0 || k <= static_cast<std::int64_t>(most)) return true;
  check.issue(
      at, std::to_string(k),
      "an integer from " + std::to_string(least) + " to " + std::to_string(most) + " (2n, at most 32): " + meaning);
  return false;
}

std::shared_ptr<const Indicator> read_lyapunov(Checker& check, const json& value, const std::string& path,
                                               std::size_t dimension, Analysis& analysis) {
  const std::size_t issues = check.issue_count();
  const KeyReader keys(check, value, path, lyapunov_keys(),
                       "an object {\"vectors\": k, \"renormalize_every\": m, \"every\": s}");
  LyapunovAnalysis lyapunov;
  if (const auto k = keys.integer("vectors"); k && within_dimension(check, *k, 1, dimension, keys.path("vectors"),
                                                                    "the number of largest exponents (default 1)"))
    lyapunov.vectors = static_cast<std::size_t>(*k);
  if (const auto m = keys.integer("renormalize_every")) lyapunov.renormalize_every = static_cast<std::uint64_t>(*m);
  if (const auto every = keys.integer("every")) lyapunov.every = static_cast<std::uint64_t>(*every);
  if (check.issue_count() != issues) return nullptr;
  analysis.lyapunov = lyapunov;
  return std::make_shared<LyapunovIndicator>(lyapunov.vectors);
}

// /analysis/frequencies: a frequency map of the signals it names (every degree of freedom when it names none).
std::shared_ptr<const Indicator> read_frequencies(Checker& check, const json& value, const std::string& path,
                                                  std::size_t dimension, Analysis&) {
  const std::size_t issues = check.issue_count();
  const KeyReader keys(check, value, path, frequencies_keys(),
                       "an object {\"every\": k, \"signals\": [degrees of freedom], \"spectra\": m}");
  if (!keys.is_object()) return nullptr;
  std::uint64_t every = 1;
  std::size_t spectra = 0;
  std::vector<std::size_t> chosen;  // the degrees of freedom, in column order
  if (const auto k = keys.integer("every")) every = static_cast<std::uint64_t>(*k);
  if (const auto m = keys.integer("spectra")) spectra = static_cast<std::size_t>(*m);
  const std::string degrees = dimension > 0 ? "from 0 to " + std::to_string(dimension - 1) : "below the dimension";
  if (keys.given("signals")) {  // distinct integers >= 0 by the table; each below the dimension here
    for (const auto& [i, item] : keys.accepted_items("signals")) {
      const auto degree = static_cast<std::size_t>(*integral_value(*item));
      if (dimension > 0 && degree >= dimension)
        check.issue(child(keys.path("signals"), i), std::to_string(degree),
                    "a degree of freedom " + degrees + " (numbered from 0)");
      else
        chosen.push_back(degree);
    }
  } else if (!keys.given("signals")) {
    for (std::size_t k = 0; k < dimension; ++k) chosen.push_back(k);
  }
  if (check.issue_count() != issues) return nullptr;
  return std::make_shared<const FrequencyMapIndicator>(every, std::move(chosen), spectra);
}

// A boolean key (its value checked by /analysis's table): `make` the indicator it asks for when true.
template <class Made>
std::shared_ptr<const Indicator> when_true(const json& value, Made&& make) {
  return value.get<bool>() ? make() : nullptr;
}

}  // namespace

const std::vector<IndicatorEntry>& indicator_entries() {
  static const std::vector<IndicatorEntry> entries{
      {KeyRule{.name = "frequencies",
               .type = ValueType::object,
               .description =
                   "Frequency map analysis (Laskar): the fundamental frequency of each signal q_k + i p_k, sampled "
                   "every `every` steps, by NAFF (Hann window) over the whole run and over its first and second "
                   "half, and the diffusion index log10 |nu_second - nu_first| / max(|nu_first|, |nu_second|): "
                   "trajectories.csv columns frequency<k>, frequency<k>_first, frequency<k>_second (radians per unit "
                   "time) and diffusion; the sampled signals in frequency_signals.npy; with spectra, the strongest "
                   "terms in frequency_spectra.csv. Needs at least 32 samples. Any model: no Hessians needed.",
               .keys = frequencies_keys},
       read_frequencies},
      {KeyRule{.name = "lyapunov",
               .type = ValueType::object,
               .description =
                   "Finite-time Lyapunov exponents (Benettin et al.) from the exact tangent map of the run's "
                   "integrator: trajectories.csv columns lyapunov0 .. lyapunov<k-1>. The plugin must have "
                   "Hessians. The first tangent vector is (1, 1/2, ..., 1/(2n)) over (dq, dp), normalised.",
               .keys = lyapunov_keys},
       read_lyapunov},
      {KeyRule{.name = "megno",
               .type = ValueType::boolean,
               .default_value = false,
               .description =
                   "MEGNO of the first tangent vector (Cincotta and Simo): trajectories.csv columns megno (Y) and "
                   "mean_megno (<Y>: -> 2 on quasi-periodic orbits, ~ lambda t / 2 on chaotic ones). The plugin "
                   "must have Hessians.",
               .allowed = "true or false: MEGNO of the first tangent vector (trajectories.csv megno, mean_megno)"},
       [](Checker&, const json& value, const std::string&, std::size_t, Analysis&) {
         return when_true(value, [] { return std::make_shared<const MegnoIndicator>(); });
       }},
      {KeyRule{.name = "sali",
               .type = ValueType::boolean,
               .default_value = false,
               .description =
                   "SALI of the first two tangent vectors (Skokos 2001), min(|u1 + u2|, |u1 - u2|) of their unit "
                   "vectors: trajectories.csv column sali (-> 0 exponentially on chaotic orbits, stays away from 0 "
                   "on regular ones). Shares the vectors of lyapunov (at least 2). The plugin must have Hessians.",
               .allowed = "true or false: SALI of the first two tangent vectors (trajectories.csv sali)"},
       [](Checker&, const json& value, const std::string&, std::size_t, Analysis&) {
         return when_true(value, [] { return std::make_shared<const AlignmentIndicator>(AlignmentIndicator::sali()); });
       }},
      {KeyRule{.name = "gali",
               .type = ValueType::integer,
               .minimum = 2,
               .maximum = static_cast<std::int64_t>(LyapunovRecord::max_exponents),
               .description =
                   "k (at most 2n): GALI_2 .. GALI_k (Skokos, Bountis and Antonopoulos 2007), the volume spanned "
                   "by the unit vectors of the first j tangent vectors: trajectories.csv columns gali2 .. gali<k> "
                   "(exponential decay on chaotic orbits; constant for j <= N, ~ t^(-2(j-N)) on an N-torus). Shares "
                   "the vectors of lyapunov. The plugin must have Hessians.",
               .allowed = "an integer from 2 to 2n (at most 32): GALI_2 .. GALI_k of the first k tangent vectors "
                          "(trajectories.csv gali2 .. gali<k>)"},
       [](Checker& check, const json& value, const std::string& path, std::size_t dimension,
          Analysis&) -> std::shared_ptr<const Indicator> {
         const std::int64_t k = *integral_value(value);
         if (!within_dimension(check, k, 2, dimension, path,
                               "GALI_2 .. GALI_k of the first k tangent vectors (trajectories.csv gali2 .. gali<k>)"))
           return nullptr;
         return std::make_shared<const AlignmentIndicator>(AlignmentIndicator::gali(static_cast<std::size_t>(k)));
       }},
      {KeyRule{.name = "fli",
               .type = ValueType::boolean,
               .default_value = false,
               .description =
                   "The fast Lyapunov indicator of the first tangent vector (Froeschle, Lega and Gonczi 1997): "
                   "trajectories.csv column fli, the supremum over the steps of ln |w(t)| with |w(0)| = 1 (~ lambda "
                   "t on chaotic orbits, ~ ln t on regular ones). The plugin must have Hessians.",
               .allowed = "true or false: the fast Lyapunov indicator of the first tangent vector (trajectories.csv "
                          "fli)"},
       [](Checker&, const json& value, const std::string&, std::size_t, Analysis&) {
         return when_true(value, [] { return std::make_shared<const FastLyapunovIndicator>(); });
       }},
      {KeyRule{.name = "ofli",
               .type = ValueType::boolean,
               .default_value = false,
               .description =
                   "The orthogonal fast Lyapunov indicator (Fouchard, Lega, Froeschle and Froeschle 2002): "
                   "trajectories.csv column ofli, the supremum over the steps of ln |w_perp(t)|, w_perp the first "
                   "tangent vector's component across the flow J grad H, |w_perp(0)| = 1 (~ lambda t on chaotic "
                   "orbits, ~ ln t on regular ones, bounded on periodic ones). One gradient of H per state and "
                   "step: the plugin must have Hessians and third derivatives, or be given by H.",
               .allowed = "true or false: the orthogonal fast Lyapunov indicator of the first tangent vector "
                          "(trajectories.csv ofli)"},
       [](Checker&, const json& value, const std::string&, std::size_t, Analysis&) {
         return when_true(value, [] { return std::make_shared<const OrthogonalFastLyapunovIndicator>(); });
       }},
  };
  return entries;
}

}  // namespace nonsep::host::job_reader
