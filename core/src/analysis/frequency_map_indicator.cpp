// Frequency map analysis as an indicator (frequency_map_indicator.hpp).
#include "nonsep/core/analysis/frequency_map_indicator.hpp"

#include "nonsep/core/base/error.hpp"

namespace nonsep {

FrequencyMapIndicator::FrequencyMapIndicator(std::uint64_t every, std::vector<std::size_t> degrees, std::size_t spectra)
    : every_(every), degrees_(std::move(degrees)), spectra_(spectra) {}

IndicatorNeeds FrequencyMapIndicator::needs() const {
  return {.samples = {.every = every_,
                      .degrees = degrees_,
                      .minimum = minimum_samples,
                      .file = signals_file_name,
                      .spectra_file = spectra_ > 0 ? spectra_file_name : ""}};
}

std::vector<std::string> FrequencyMapIndicator::columns() const {
  std::vector<std::string> names;
  for (std::size_t k : degrees_)
    for (const char* part : {"", "_first", "_second"}) names.push_back("frequency" + std::to_string(k) + part);
  names.push_back("diffusion");
  return names;
}

std::string FrequencyMapIndicator::description() const {
  return "trajectories.csv frequency<k>, frequency<k>_first, frequency<k>_second for each signal, diffusion";
}

SampleAnalysis FrequencyMapIndicator::from_samples(std::span<const std::span<const std::complex<double>>> signals,
                                                   double tau) const {
  thread_local FrequencyAnalysis analysis;
  SampleAnalysis result;
  const std::size_t m = signals.size();
  std::vector<double> whole(m), first(m), second(m);
  try {
    for (std::size_t j = 0; j < m; ++j) {
      const std::span<const std::complex<double>> z = signals[j];
      const std::size_t half = z.size() / 2;
      // The column is the strongest term alone: the amplitudes of several terms found together are their joint
      // projection, which can rank a later term first.
      whole[j] = analysis.fundamental_frequency(z, tau);
      if (spectra_ > 0) result.spectra.push_back(analysis.terms(z, tau, spectra_));
      first[j] = analysis.fundamental_frequency(z.first(half), tau);
      second[j] = analysis.fundamental_frequency(z.subspan(half, half), tau);
    }
  } catch (const InvalidArgument&) {
    return {};  // a sample that is not finite: no analysis
  }
  for (std::size_t j = 0; j < m; ++j) result.values.insert(result.values.end(), {whole[j], first[j], second[j]});
  result.values.push_back(diffusion_index(first, second));
  return result;
}

}  // namespace nonsep
