#pragma once
// One chunk of an HDF5 dataset whose filter pipeline is shuffle then deflate (H5Pset_shuffle, H5Pset_deflate),
// filtered by our code instead of HDF5's, for H5Dwrite_chunk: the bytes any HDF5 reader (h5py, h5dump) turns back
// into the chunk's numbers with the dataset's declared filters.
//
// In:  a chunk of `count` elements of `element_size` bytes each (native byte order as stored: little-endian doubles).
// Out: shuffle (byte k of every element together: plane k is bytes k, k + size, k + 2 size, ...), then one zlib
//      stream (RFC 1950, what the deflate filter inflates) of the planes in order. Each plane is deflated at
//      `level` when deflating trial_bytes of it (trial_pieces pieces spread evenly over the plane) at that level
//      shrinks them to at most keep_fraction of their size; otherwise it goes into the stream as stored blocks
//      (deflate level 0: a copy and a checksum). The choice is switched between planes with deflateParams, in the
//      same stream.
//
// Why: the planes of the low mantissa bytes of computed doubles are close to random; deflating them costs most of
// deflate's time (measured: on the benchmark's 10^5 paper2d orbits 84% of the time, for 5% of the size) and
// gains nearly nothing, while the sign/exponent planes compress 5 to 100 times. The trial finds the few mantissa
// planes that do compress (a grid's initial values, constants, NaN where a trajectory stopped). The result is
// deterministic: the same chunk gives the same bytes (zlib's output depends only on its input and parameters).
//
// One object per thread; it keeps its zlib streams and buffers between chunks. Throws std::runtime_error when zlib
// fails (only when it cannot allocate its state).
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

struct z_stream_s;  // zlib.h's z_stream, kept out of this header

namespace nonsep::host {

class ShuffleDeflate {
 public:
  static constexpr std::size_t trial_bytes = 1024, trial_pieces = 4;
  static constexpr double keep_fraction = 0.9;

  explicit ShuffleDeflate(int level);

  // The filtered chunk; valid until the next call.
  std::span<const unsigned char> filter(std::span<const unsigned char> chunk, std::size_t element_size);

  // How many planes of the last chunk were deflated (the rest were stored); for tests and measurements.
  std::size_t deflated_planes() const { return deflated_planes_; }

 private:
  struct EndStream {
    void operator()(z_stream_s* stream) const;
  };
  using Stream = std::unique_ptr<z_stream_s, EndStream>;
  static Stream start_stream(int level);
  bool worth_deflating(std::span<const unsigned char> plane);
  void deflate_all(int flush);  // stream_'s input into output_, which grows as needed
  void grow_output();           // doubles output_, keeping what stream_ wrote

  int level_;
  Stream stream_, trial_;
  std::vector<unsigned char> shuffled_, output_, trial_input_, trial_output_;
  std::size_t deflated_planes_ = 0;
};

}  // namespace nonsep::host
