#pragma once
// The sample store of an indicator that needs samples of the state (nonsep::Indicator, needs().samples; frequency
// map analysis is one: nonsep::FrequencyMapIndicator): it samples the signals z_k = q_k + i p_k of the degrees of
// freedom the indicator names, keeps them, and hands a trajectory's samples to the indicator's from_samples() when
// they are complete; the indicator's columns go to trajectories.csv, its spectra to its spectra file.
//
// Sampling: an observer of every `every`-th step (StepObserver), on the worker threads; the signals are sampled at
// steps every, 2 every, ..., N every with N = steps / every (at least the indicator's minimum: the job reader checks
// it), so tau = every dt.
//
// Where the samples go: the indicator's sample file (frequency_signals.npy), a NumPy array of complex128
// (little-endian) of shape (trajectories, signals, N), trajectory by trajectory, created at its full size (sparse)
// and filled as the run goes: the samples are kept in memory per trajectory and signal and written (pwrite) once
// there are samples_in_memory (job.hpp: 16 kB) of them, and all of them before a checkpoint, at a trajectory's
// retirement and at the end; a chunk that the driver redoes step by step is forgotten (restore_block: what was kept
// before the chunk stays). Memory holds some 16 kB per trajectory and signal, not the run's samples. A trajectory
// that stops early keeps zeros after its last sample. The file is a result of its own (numpy.load(...,
// mmap_mode="r")), and what a resumed run reads its samples back from.
//
// When the indicator's values are computed: when a trajectory takes its N-th sample, on the worker thread of its
// block (so the analyses of an ensemble run in parallel; a redone chunk computes them again); a trajectory that
// completes early (a Poincare section's max_crossings) is analysed when it retires, from the samples it has, if at
// least the minimum. A trajectory that stops otherwise ("diverged", "failed", "inaccurate") or is interrupted (a
// resumed run finishes it) is not analysed, nor one the indicator cannot analyse (a sample that is not finite): its
// cells are empty.
//
// The spectra file (with an indicator that has one: frequency_spectra.csv) holds the strongest terms of each signal:
//   trajectory,signal,term,frequency,amplitude_re,amplitude_im
// in trajectory order (written whole at the end of the run, also of a failed or interrupted one).
//
// Checkpoints (under the indicator's name): per trajectory the samples written so far and a checksum of each signal's
// samples (64-bit FNV-1a over the samples' 8-byte words), and the analyses already done (their numbers as shortest
// round-trip strings); a resume checks the file's header and every checksum against the file before it continues.
#include <array>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "nonsep/core/analysis/indicator.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/run/observer.hpp"
#include "nonsep/host/time_grid.hpp"

namespace nonsep::host {

class SampledIndicatorObserver : public Observer,
                                 public ChunkObserver,
                                 public StepObserver,
                                 public CheckpointedObserver,
                                 public TrajectoryColumns {
 public:
  // Creates the indicator's sample file in `directory` at its full size, or, when `resuming`, opens the one there
  // (its header must be this run's). Throws OutputError, and InvalidArgument for a signal beyond `dimension`.
  SampledIndicatorObserver(const std::filesystem::path& directory, std::shared_ptr<const Indicator> indicator,
                           const TimeGrid& time, std::size_t dimension, std::size_t trajectories, bool resuming);
  SampledIndicatorObserver(const SampledIndicatorObserver&) = delete;
  SampledIndicatorObserver& operator=(const SampledIndicatorObserver&) = delete;
  ~SampledIndicatorObserver() override;

  void on_retire(std::size_t trajectory, const TrajectoryRecord& record) override;
  void on_end() override;

  void prepare_blocks(std::size_t blocks) override;
  void after_chunk(std::uint64_t step) override;

  std::uint64_t stride() const override { return every_; }
  void on_step(std::uint64_t step, double t, const BlockView& block) override;
  void save_block(const BlockView& block) override;
  void restore_block(const BlockView& block) override;

  std::string name() const override { return indicator_->name(); }
  nlohmann::json save() override;
  void restore(const nlohmann::json& state) override;

  void columns(std::vector<std::string>& names) const override;
  void cells(std::size_t trajectory, std::string& row) const override;

  // The sample file's header (NumPy format 1.0, padded to 64 bytes) for an array of that shape, and the shape
  // (trajectories, signals, samples) that such a header gives, or nothing when it is not one of them.
  static std::string signals_header(std::uint64_t trajectories, std::uint64_t signals, std::uint64_t samples);
  static std::optional<std::array<std::uint64_t, 3>> signals_shape(const std::string& header);

  const Indicator& indicator() const { return *indicator_; }
  const std::vector<std::size_t>& signals() const { return signals_; }  // degrees of freedom, in column order
  std::uint64_t samples() const { return samples_; }                    // N, per signal
  double tau() const { return tau_; }
  // Trajectories analysed so far.
  std::size_t analysed() const;

 private:
  // One trajectory's analysis: from `samples` samples of each signal (0: none yet).
  struct Result {
    std::uint64_t samples = 0;
    SampleAnalysis analysis;  // its columns' values, in order, and per signal the strongest terms of the whole run
  };
  // What one block's worker thread owns: the samples of each signal of the trajectory it analyses.
  struct BlockState {
    std::vector<std::vector<std::complex<double>>> samples;
  };

  std::uint64_t count(std::size_t trajectory) const;
  void flush(std::size_t trajectory);
  void flush_all();
  // The first `count` samples of `signal` of `trajectory`, from the file and from memory.
  void read(std::size_t trajectory, std::size_t signal, std::uint64_t count,
            std::vector<std::complex<double>>& samples) const;
  Result analyse(std::size_t trajectory, std::uint64_t count, BlockState& state) const;
  std::uint64_t offset(std::size_t trajectory, std::size_t signal, std::uint64_t sample) const;
  void write_spectra() const;

  std::shared_ptr<const Indicator> indicator_;
  std::uint64_t every_;
  std::vector<std::size_t> signals_;
  std::size_t columns_;  // the indicator's
  double tau_;
  std::size_t dimension_;
  std::size_t trajectories_;
  std::uint64_t samples_;
  std::filesystem::path signals_path_, spectra_path_;
  int descriptor_ = -1;
  std::uint64_t data_offset_ = 0;                           // the header's size
  std::vector<std::uint64_t> written_;                      // per trajectory: samples of each signal in the file
  std::vector<std::uint64_t> checksums_;                    // per trajectory and signal: of those samples
  std::vector<std::vector<std::complex<double>>> pending_;  // per trajectory and signal: samples not yet written
  std::vector<std::uint64_t> chunk_start_;                  // per trajectory: its samples when the chunk began
  std::vector<Result> results_;                             // per trajectory
  std::vector<BlockState> blocks_;
  BlockState own_;  // for analyses on the driver's thread (on_retire)
};

}  // namespace nonsep::host
