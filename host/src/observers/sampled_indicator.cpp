#include "nonsep/host/observers/sampled_indicator.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <regex>

#include "nonsep/core/base/error.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/content_hash.hpp"
#include "nonsep/host/run/saved_state.hpp"

namespace nonsep::host {

namespace {

constexpr std::uint64_t sample_bytes = sizeof(std::complex<double>);

// The samples' checksum: 64-bit FNV-1a over their 8-byte words (a word at a time: the file can be large).
std::uint64_t checksum(std::span<const std::complex<double>> samples, std::uint64_t hash) {
  for (const std::complex<double>& z : samples)
    for (double x : {z.real(), z.imag()}) {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &x, sizeof bits);
      hash = (hash ^ bits) * 1099511628211ull;
    }
  return hash;
}

// The indicator's signals, each a degree of freedom of the states (the job reader names them all when the job names
// none), at least one.
std::vector<std::size_t> checked_signals(const Indicator& indicator, std::size_t dimension) {
  std::vector<std::size_t> signals = indicator.needs().samples.degrees;
  if (signals.empty()) throw InvalidArgument(indicator.name() + ": no signal to sample");
  for (std::size_t k : signals)
    if (k >= dimension)
      throw InvalidArgument(indicator.name() + ": the signal of degree of freedom " + std::to_string(k) +
                            " of a state of dimension " + std::to_string(dimension));
  return signals;
}

}  // namespace

SampledIndicatorObserver::SampledIndicatorObserver(const std::filesystem::path& directory,
                                                   std::shared_ptr<const Indicator> indicator, const TimeGrid& time,
                                                   std::size_t dimension, std::size_t trajectories, bool resuming)
    : indicator_(std::move(indicator)),
      every_(indicator_->needs().samples.every),
      signals_(checked_signals(*indicator_, dimension)),
      columns_(indicator_->columns().size()),
      tau_(static_cast<double>(every_) * time.dt),
      dimension_(dimension),
      trajectories_(trajectories),
      samples_(time.steps / every_),
      signals_path_(directory / indicator_->needs().samples.file),
      written_(trajectories, 0),
      checksums_(trajectories * signals_.size(), content_hash_start),
      pending_(trajectories * signals_.size()),
      chunk_start_(trajectories, 0),
      results_(trajectories) {
  if (const std::string spectra = indicator_->needs().samples.spectra_file; !spectra.empty())
    spectra_path_ = directory / spectra;
  const std::string header = signals_header(trajectories, signals_.size(), samples_);
  data_offset_ = header.size();
  const std::uint64_t rows = static_cast<std::uint64_t>(trajectories) * signals_.size();
  if (rows > 0 && samples_ > (std::numeric_limits<std::int64_t>::max() / sample_bytes - data_offset_) / rows)
    throw OutputError("cannot create " + signals_path_.string() + ": " + std::to_string(rows) + " signals of " +
                      std::to_string(samples_) +
                      " samples are more than a file can hold; sample less often (/analysis/" + indicator_->name() +
                      "/every)");
  const std::uint64_t size = data_offset_ + rows * samples_ * sample_bytes;
  const std::string verb = resuming ? "cannot resume " : "cannot create ";
  descriptor_ = open_regular_file_for_writing(signals_path_, O_RDWR | (resuming ? 0 : O_CREAT | O_TRUNC), verb);
  const auto refuse = [&](const std::string& reason) {
    ::close(descriptor_);
    descriptor_ = -1;
    throw OutputError(verb + signals_path_.string() + ": " + reason);
  };
  struct stat status {};
  if (::fstat(descriptor_, &status) != 0) refuse(std::strerror(errno));
  if (resuming) {
    std::string found(header.size(), '\0');
    if (static_cast<std::uint64_t>(status.st_size) != size ||
        ::pread(descriptor_, found.data(), found.size(), 0) != static_cast<ssize_t>(found.size()) || found != header)
      refuse(
          "it is not the array of this run's signals (another run wrote into this folder, or the file was "
          "edited); run with --force to start over");
    return;
  }
  if (::pwrite(descriptor_, header.data(), header.size(), 0) != static_cast<ssize_t>(header.size()) ||
      ::ftruncate(descriptor_, static_cast<off_t>(size)) != 0)
    refuse(std::strerror(errno));
}

std::string SampledIndicatorObserver::signals_header(std::uint64_t trajectories, std::uint64_t signals,
                                                     std::uint64_t samples) {
  std::string dictionary = "{'descr': '<c16', 'fortran_order': False, 'shape': (" + std::to_string(trajectories) +
                           ", " + std::to_string(signals) + ", " + std::to_string(samples) + "), }";
  const std::size_t unpadded = 10 + dictionary.size() + 1;
  dictionary.append((64 - unpadded % 64) % 64, ' ');
  dictionary += '\n';
  std::string header("\x93NUMPY\x01\x00", 8);
  header += static_cast<char>(dictionary.size() & 0xff);
  header += static_cast<char>(dictionary.size() >> 8);
  return header + dictionary;
}

std::optional<std::array<std::uint64_t, 3>> SampledIndicatorObserver::signals_shape(const std::string& header) {
  static const std::regex form(
      "\\{'descr': '<c16', 'fortran_order': False, 'shape': \\(([0-9]{1,19}), ([0-9]{1,19}), "
      "([0-9]{1,19})\\), \\} *\n");
  std::smatch match;
  if (header.size() < 10 || header.compare(0, 8, std::string("\x93NUMPY\x01\x00", 8)) != 0) return std::nullopt;
  const std::string dictionary = header.substr(10);
  if (!std::regex_match(dictionary, match, form)) return std::nullopt;
  std::array<std::uint64_t, 3> shape{};
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string digits = match[i + 1].str();
    if (std::from_chars(digits.data(), digits.data() + digits.size(), shape[i]).ec != std::errc()) return std::nullopt;
  }
  if (signals_header(shape[0], shape[1], shape[2]) != header) return std::nullopt;
  return shape;
}

SampledIndicatorObserver::~SampledIndicatorObserver() {
  if (descriptor_ >= 0) ::close(descriptor_);
}

std::uint64_t SampledIndicatorObserver::offset(std::size_t trajectory, std::size_t signal, std::uint64_t sample) const {
  return data_offset_ +
         ((static_cast<std::uint64_t>(trajectory) * signals_.size() + signal) * samples_ + sample) * sample_bytes;
}

std::uint64_t SampledIndicatorObserver::count(std::size_t trajectory) const {
  return written_[trajectory] + pending_[trajectory * signals_.size()].size();
}

void SampledIndicatorObserver::flush(std::size_t trajectory) {
  const std::size_t m = signals_.size();
  const std::uint64_t added = pending_[trajectory * m].size();
  if (added == 0) return;
  for (std::size_t j = 0; j < m; ++j) {
    std::vector<std::complex<double>>& samples = pending_[trajectory * m + j];
    const char* bytes = reinterpret_cast<const char*>(samples.data());
    std::uint64_t done = 0, total = samples.size() * sample_bytes;
    while (done < total) {
      const ssize_t n = ::pwrite(descriptor_, bytes + done, total - done,
                                 static_cast<off_t>(offset(trajectory, j, written_[trajectory]) + done));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw OutputError("cannot write " + signals_path_.string() + ": " + std::strerror(errno));
      done += static_cast<std::uint64_t>(n);
    }
    checksums_[trajectory * m + j] = checksum(samples, checksums_[trajectory * m + j]);
    samples.clear();
  }
  written_[trajectory] += added;
}

void SampledIndicatorObserver::flush_all() {
  for (std::size_t trajectory = 0; trajectory < trajectories_; ++trajectory) flush(trajectory);
}

void SampledIndicatorObserver::read(std::size_t trajectory, std::size_t signal, std::uint64_t count,
                                    std::vector<std::complex<double>>& samples) const {
  samples.resize(count);
  const std::uint64_t from_file = std::min(count, written_[trajectory]);
  char* bytes = reinterpret_cast<char*>(samples.data());
  std::uint64_t done = 0, total = from_file * sample_bytes;
  while (done < total) {
    const ssize_t n =
        ::pread(descriptor_, bytes + done, total - done, static_cast<off_t>(offset(trajectory, signal, 0) + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw OutputError("cannot read " + signals_path_.string() + ": " +
                        (n == 0 ? std::string("it is shorter than it was written") : std::strerror(errno)));
    done += static_cast<std::uint64_t>(n);
  }
  const auto& pending = pending_[trajectory * signals_.size() + signal];
  std::copy_n(pending.begin(), count - from_file, samples.begin() + static_cast<std::ptrdiff_t>(from_file));
}

SampledIndicatorObserver::Result SampledIndicatorObserver::analyse(std::size_t trajectory, std::uint64_t count,
                                                                   BlockState& state) const {
  Result result;
  result.samples = count;
  if (count < indicator_->needs().samples.minimum) return result;
  const std::size_t m = signals_.size();
  state.samples.resize(m);
  std::vector<std::span<const std::complex<double>>> signals(m);
  for (std::size_t j = 0; j < m; ++j) {
    read(trajectory, j, count, state.samples[j]);
    signals[j] = state.samples[j];
  }
  result.analysis = indicator_->from_samples(signals, tau_);
  return result;
}

void SampledIndicatorObserver::prepare_blocks(std::size_t blocks) { blocks_.resize(blocks); }

void SampledIndicatorObserver::on_step(std::uint64_t step, double, const BlockView& block) {
  const std::uint64_t sample = step / every_;  // 1-based
  if (step % every_ != 0 || sample == 0 || sample > samples_) return;
  const std::size_t n = dimension_, m = signals_.size();
  for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
    const std::size_t trajectory = block.trajectories[slot];
    if (count(trajectory) != sample - 1) continue;  // never: every sample step is seen once
    for (std::size_t j = 0; j < m; ++j) {
      const std::size_t k = signals_[j];
      pending_[trajectory * m + j].emplace_back(block.q[slot * n + k], block.p[slot * n + k]);
    }
    if (sample == samples_) results_[trajectory] = analyse(trajectory, sample, blocks_[block.block]);
  }
}

void SampledIndicatorObserver::save_block(const BlockView& block) {
  for (std::size_t trajectory : block.trajectories) chunk_start_[trajectory] = count(trajectory);
}

void SampledIndicatorObserver::restore_block(const BlockView& block) {
  const std::size_t m = signals_.size();
  for (std::size_t trajectory : block.trajectories) {
    const std::uint64_t kept = chunk_start_[trajectory] - written_[trajectory];  // pending before the chunk
    for (std::size_t j = 0; j < m; ++j) pending_[trajectory * m + j].resize(kept);
    if (results_[trajectory].samples > chunk_start_[trajectory]) results_[trajectory] = {};
  }
}

void SampledIndicatorObserver::after_chunk(std::uint64_t) {
  // A write per trajectory and signal once it has some 16 kB: a write per chunk each would cost some 3% of a run
  // that samples every step.
  for (std::size_t trajectory = 0; trajectory < trajectories_; ++trajectory)
    if (pending_[trajectory * signals_.size()].size() >= samples_in_memory) flush(trajectory);
}

void SampledIndicatorObserver::on_retire(std::size_t trajectory, const TrajectoryRecord& record) {
  flush(trajectory);
  if (record.status != TrajectoryStatus::completed) {
    results_[trajectory] = {};  // stopped by its numbers or interrupted: no analysis
    return;
  }
  if (results_[trajectory].samples != written_[trajectory] || written_[trajectory] == 0)
    results_[trajectory] = analyse(trajectory, written_[trajectory], own_);
}

void SampledIndicatorObserver::on_end() {
  flush_all();
  if (!spectra_path_.empty()) write_spectra();
}

std::size_t SampledIndicatorObserver::analysed() const {
  return static_cast<std::size_t>(
      std::count_if(results_.begin(), results_.end(), [](const Result& r) { return !r.analysis.values.empty(); }));
}

void SampledIndicatorObserver::write_spectra() const {
  std::string text = "trajectory,signal,term,frequency,amplitude_re,amplitude_im\n";
  for (std::size_t trajectory = 0; trajectory < trajectories_; ++trajectory)
    for (std::size_t j = 0; j < results_[trajectory].analysis.spectra.size(); ++j) {
      const auto& terms = results_[trajectory].analysis.spectra[j];
      for (std::size_t term = 0; term < terms.size(); ++term) {
        text += std::to_string(trajectory) + ',' + std::to_string(signals_[j]) + ',' + std::to_string(term) + ',';
        append_number(text, terms[term].frequency);
        text += ',';
        append_number(text, terms[term].amplitude.real());
        text += ',';
        append_number(text, terms[term].amplitude.imag());
        text += '\n';
      }
    }
  write_file_atomically(spectra_path_, text);
}

nlohmann::json SampledIndicatorObserver::save() {
  flush_all();
  nlohmann::json checksums = nlohmann::json::array(), results = nlohmann::json::array();
  for (std::uint64_t hash : checksums_) checksums.push_back(content_hash_hex(hash));
  for (std::size_t trajectory = 0; trajectory < trajectories_; ++trajectory) {
    const Result& result = results_[trajectory];
    if (result.samples == 0) continue;
    nlohmann::json values = nlohmann::json::array(), spectra = nlohmann::json::array();
    for (double x : result.analysis.values) values.push_back(format_number(x));
    for (const auto& terms : result.analysis.spectra) {
      nlohmann::json numbers = nlohmann::json::array();
      for (const FrequencyTerm& term : terms)
        for (double x : {term.frequency, term.amplitude.real(), term.amplitude.imag()})
          numbers.push_back(format_number(x));
      spectra.push_back(std::move(numbers));
    }
    results.push_back(
        {{"trajectory", trajectory}, {"samples", result.samples}, {"values", values}, {"spectra", spectra}});
  }
  return {{"samples", written_}, {"checksums", checksums}, {"results", results}};
}

void SampledIndicatorObserver::restore(const nlohmann::json& state) {
  const SavedState saved = SavedState::of_observer(name(), state);
  const std::size_t m = signals_.size();
  const nlohmann::json& counts = saved.list(saved.member(state, "samples"), trajectories_, "samples");
  const nlohmann::json& sums = saved.list(saved.member(state, "checksums"), trajectories_ * m, "checksums");
  for (std::size_t trajectory = 0; trajectory < trajectories_; ++trajectory)
    written_[trajectory] = saved.count(counts[trajectory], "a sample count", samples_);
  for (std::size_t i = 0; i < sums.size(); ++i)
    if (!sums[i].is_string() || sums[i].get<std::string>().size() != 16) saved.damaged("a checksum");
  const nlohmann::json& results = saved.member(state, "results");
  if (!results.is_array()) saved.damaged("results that are not a list");
  for (const nlohmann::json& entry : results) {
    const std::size_t trajectory = saved.count(saved.member(entry, "trajectory"), "a trajectory", trajectories_ - 1);
    Result& result = results_[trajectory];
    result.samples = saved.count(saved.member(entry, "samples"), "a sample count", written_[trajectory]);
    const nlohmann::json& values = saved.member(entry, "values");
    result.analysis.values = saved.numbers(values, values.is_array() && values.empty() ? 0 : columns_, "values");
    const nlohmann::json& spectra = saved.member(entry, "spectra");
    const nlohmann::json& lists = saved.list(spectra, spectra.is_array() && spectra.empty() ? 0 : m, "spectra");
    result.analysis.spectra.clear();
    for (const nlohmann::json& list : lists) {
      const std::size_t terms = list.is_array() ? list.size() / 3 : 0;
      const std::vector<double> numbers = saved.numbers(list, 3 * terms, "a spectrum");
      auto& out = result.analysis.spectra.emplace_back();
      for (std::size_t t = 0; t < terms; ++t) out.push_back({numbers[3 * t], {numbers[3 * t + 1], numbers[3 * t + 2]}});
    }
  }
  // The file's samples must be the ones the checkpoint counted.
  std::vector<std::complex<double>> samples;
  for (std::size_t trajectory = 0; trajectory < trajectories_; ++trajectory)
    for (std::size_t j = 0; j < m; ++j) {
      read(trajectory, j, written_[trajectory], samples);
      const std::uint64_t hash = checksum(samples, content_hash_start);
      if (content_hash_hex(hash) != sums[trajectory * m + j].get<std::string>())
        throw OutputError("cannot resume " + signals_path_.string() + ": the samples of trajectory " +
                          std::to_string(trajectory) +
                          " are not the ones the checkpoint recorded (another run wrote into this folder, or the "
                          "file was edited); run with --force to start over");
      checksums_[trajectory * m + j] = hash;
    }
}

void SampledIndicatorObserver::columns(std::vector<std::string>& names) const {
  for (std::string& column : indicator_->columns()) names.push_back(std::move(column));
}

void SampledIndicatorObserver::cells(std::size_t trajectory, std::string& row) const {
  const std::vector<double>& values = results_[trajectory].analysis.values;
  for (std::size_t j = 0; j < columns_; ++j) {
    row += ',';
    if (j < values.size()) append_number(row, values[j]);
  }
}

}  // namespace nonsep::host
