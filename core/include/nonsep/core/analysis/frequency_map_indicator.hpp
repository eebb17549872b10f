#pragma once
// Frequency map analysis (Laskar 1990, 1993) as an indicator that needs samples of the state (indicator.hpp): for
// each signal z_k = q_k + i p_k of the degrees of freedom it names, the fundamental frequency by NAFF
// (frequency_analysis.hpp) over the whole run and over its first and second half, and Laskar's diffusion index of the
// two halves (diffusion_index: Euclidean norms over the signals).
//
// Columns, per signal k in order: frequency<k> (the whole run), frequency<k>_first, frequency<k>_second (the halves:
// samples 0 .. N/2 - 1 and N/2 .. 2 (N/2) - 1 of N), in radians per unit time, signed (FrequencyAnalysis's
// conventions); then diffusion. With spectra m >= 1 the m strongest terms of each signal over the whole run go to
// its spectra file. A trajectory with a sample that is not finite gets no values.
//
// The analyses of one thread share one FrequencyAnalysis (its FFT tables and windows per length; the numbers do not
// depend on what it analysed before).
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "nonsep/core/analysis/indicator.hpp"

namespace nonsep {

class FrequencyMapIndicator final : public Indicator {
 public:
  // 16 in each half: FrequencyAnalysis::minimum_samples.
  static constexpr std::uint64_t minimum_samples = 2 * FrequencyAnalysis::minimum_samples;
  static constexpr const char* signals_file_name = "frequency_signals.npy";
  static constexpr const char* spectra_file_name = "frequency_spectra.csv";

  // A sample every `every` steps of the signals of `degrees` (in column order), and `spectra` terms per signal in the
  // spectra file (0: no such file).
  FrequencyMapIndicator(std::uint64_t every, std::vector<std::size_t> degrees, std::size_t spectra);

  std::string name() const override { return "frequencies"; }
  IndicatorNeeds needs() const override;
  std::vector<std::string> columns() const override;
  std::string description() const override;
  // In this order: a checkpoint's fingerprint lists them so (host/src/checkpoint/checkpoint_file.cpp).
  std::vector<std::pair<std::string, std::size_t>> settings() const override {
    return {{"every", static_cast<std::size_t>(every_)}, {"spectra", spectra_}};
  }
  SampleAnalysis from_samples(std::span<const std::span<const std::complex<double>>> signals,
                              double tau) const override;
  std::shared_ptr<const Indicator> sampling_every(std::uint64_t every) const override {
    return std::make_shared<const FrequencyMapIndicator>(every, degrees_, spectra_);
  }

  std::uint64_t every() const { return every_; }
  const std::vector<std::size_t>& degrees() const { return degrees_; }
  std::size_t spectra() const { return spectra_; }

 private:
  std::uint64_t every_;
  std::vector<std::size_t> degrees_;
  std::size_t spectra_;
};

}  // namespace nonsep
