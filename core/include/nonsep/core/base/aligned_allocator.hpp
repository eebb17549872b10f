#pragma once
// Storage for the arrays the hot loops stream through (PhaseSpaceBatch's q and p, the integrators' gradient arrays),
// aligned to a cache line when they are long enough for it to matter. With 32- and 64-byte vectors (AVX2, AVX-512:
// a -DNONSEP_NATIVE=ON build), an array that malloc places at 16 bytes past a cache line makes every other or every
// vector load and store straddle two lines: measured on this project's AMD EPYC (Zen 4) VM, the stage-by-stage loop
// over 256 states of paper1d took 2.78 ns per state and step on such arrays and 2.22 ns on aligned ones. Portable
// (SSE2) code loses nothing either way.
#include <cstddef>
#include <new>
#include <vector>

namespace nonsep {

inline constexpr std::size_t cache_line_size = 64;

// A std::allocator whose blocks of at least `aligned_from_bytes` start on a cache line. Smaller blocks come from
// the ordinary heap: a loop over a few numbers gains nothing from alignment, and aligned allocation (glibc's
// memalign) of many small blocks fragments the heap: with every block aligned, a run that evaluates H at every step
// (it copies its one-state batch at each) spent a fifth of its time in malloc and free. A container hands
// deallocate() the size it allocated, which says where the block came from.
template <class T>
struct CacheLineAllocator {
  using value_type = T;
  static constexpr std::size_t aligned_from_bytes = 4 * cache_line_size;

  CacheLineAllocator() = default;
  template <class U>
  CacheLineAllocator(const CacheLineAllocator<U>&) noexcept {}

  static bool aligned(std::size_t n) { return n * sizeof(T) >= aligned_from_bytes; }
  T* allocate(std::size_t n) {
    if (!aligned(n)) return static_cast<T*>(::operator new(n * sizeof(T)));
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(cache_line_size)));
  }
  void deallocate(T* pointer, std::size_t n) noexcept {
    if (!aligned(n))
      ::operator delete(pointer);
    else
      ::operator delete(pointer, std::align_val_t(cache_line_size));
  }

  template <class U>
  friend bool operator==(const CacheLineAllocator&, const CacheLineAllocator<U>&) noexcept {
    return true;
  }
};

// A vector of doubles that starts on a cache line once it holds 32 or more.
using AlignedDoubles = std::vector<double, CacheLineAllocator<double>>;

}  // namespace nonsep
