#include "nonsep/host/output/shuffle_deflate.hpp"

#include <zlib.h>

#include <algorithm>
#include <climits>
#include <stdexcept>
#include <string>

namespace nonsep::host {

namespace {

[[noreturn]] void zlib_failed(const char* what, int status) {
  throw std::runtime_error(std::string("zlib: ") + what + " failed (status " + std::to_string(status) + ")");
}

unsigned to_uint(std::size_t size) {
  if (size > UINT_MAX) throw std::runtime_error("zlib: a chunk of more than 4 GiB");
  return static_cast<unsigned>(size);
}

}  // namespace

void ShuffleDeflate::EndStream::operator()(z_stream_s* stream) const {
  deflateEnd(stream);
  delete stream;
}

ShuffleDeflate::Stream ShuffleDeflate::start_stream(int level) {
  Stream stream(new z_stream_s{});
  // zlib's format (15-bit window, zlib header and Adler-32), what HDF5's deflate filter writes and inflates.
  if (const int status = deflateInit(stream.get(), level); status != Z_OK) {
    delete stream.release();  // deflateEnd is for initialised streams only
    zlib_failed("deflateInit", status);
  }
  return stream;
}

ShuffleDeflate::ShuffleDeflate(int level) : level_(level), stream_(start_stream(level)), trial_(start_stream(level)) {}

bool ShuffleDeflate::worth_deflating(std::span<const unsigned char> plane) {
  // trial_pieces pieces spread over the plane: the NaN after an edge chunk's last trajectory, or where trajectories
  // stopped, is found wherever it is.
  trial_input_.clear();
  const std::size_t piece = trial_bytes / trial_pieces;
  if (plane.size() <= trial_bytes) {
    trial_input_.assign(plane.begin(), plane.end());
  } else {
    for (std::size_t k = 0; k < trial_pieces; ++k) {
      const auto from = plane.begin() + static_cast<std::ptrdiff_t>(k * (plane.size() / trial_pieces));
      trial_input_.insert(trial_input_.end(), from, from + static_cast<std::ptrdiff_t>(piece));
    }
  }
  trial_output_.resize(deflateBound(trial_.get(), trial_input_.size()));
  deflateReset(trial_.get());
  trial_->next_in = trial_input_.data();
  trial_->avail_in = to_uint(trial_input_.size());
  trial_->next_out = trial_output_.data();
  trial_->avail_out = to_uint(trial_output_.size());
  if (const int status = deflate(trial_.get(), Z_FINISH); status != Z_STREAM_END) zlib_failed("deflate", status);
  return static_cast<double>(trial_->total_out) <= keep_fraction * static_cast<double>(trial_input_.size());
}

void ShuffleDeflate::grow_output() {
  const std::size_t used = output_.size() - stream_->avail_out;
  output_.resize(2 * output_.size() + 64);
  stream_->next_out = output_.data() + used;
  stream_->avail_out = to_uint(output_.size() - used);
}

void ShuffleDeflate::deflate_all(int flush) {
  for (;;) {
    if (stream_->avail_out == 0) grow_output();
    const int status = deflate(stream_.get(), flush);
    if (status == Z_STREAM_END) return;
    if (status != Z_OK && status != Z_BUF_ERROR) zlib_failed("deflate", status);
    if (stream_->avail_in == 0 && stream_->avail_out != 0 && flush != Z_FINISH) return;
  }
}

std::span<const unsigned char> ShuffleDeflate::filter(std::span<const unsigned char> chunk, std::size_t element_size) {
  const std::size_t count = chunk.size() / element_size;
  // HDF5's shuffle (H5Zshuffle.c): plane k holds byte k of every element; bytes after the last whole element (none
  // for our chunks) stay at the end.
  shuffled_.resize(chunk.size());
  for (std::size_t i = 0; i < count; ++i)
    for (std::size_t k = 0; k < element_size; ++k) shuffled_[k * count + i] = chunk[i * element_size + k];
  std::copy(chunk.begin() + static_cast<std::ptrdiff_t>(count * element_size), chunk.end(),
            shuffled_.begin() + static_cast<std::ptrdiff_t>(count * element_size));

  deflateReset(stream_.get());
  output_.resize(deflateBound(stream_.get(), chunk.size()) + 16 * element_size);
  stream_->next_out = output_.data();
  stream_->avail_out = to_uint(output_.size());
  deflated_planes_ = 0;
  int current = level_;
  const std::size_t planes = count > 0 ? element_size : 0;
  for (std::size_t k = 0; k < planes; ++k) {
    const std::span<const unsigned char> plane(shuffled_.data() + k * count, count);
    const bool deflated = worth_deflating(plane);
    deflated_planes_ += deflated;
    if (const int level = deflated ? level_ : 0; level != current) {
      // Compresses what the stream holds with the old level first, which needs room in the output.
      int status;
      while ((status = deflateParams(stream_.get(), level, Z_DEFAULT_STRATEGY)) == Z_BUF_ERROR) grow_output();
      if (status != Z_OK) zlib_failed("deflateParams", status);
      current = level;
    }
    stream_->next_in = const_cast<unsigned char*>(plane.data());
    stream_->avail_in = to_uint(plane.size());
    deflate_all(Z_NO_FLUSH);
  }
  stream_->next_in = shuffled_.data() + planes * count;
  stream_->avail_in = to_uint(shuffled_.size() - planes * count);
  deflate_all(Z_FINISH);
  return std::span<const unsigned char>(output_.data(), stream_->total_out);
}

}  // namespace nonsep::host
