#pragma once
// Storage for the arrays the hot loops stream through (PhaseSpaceBatch's q and p, the integrators' gradient arrays),
// aligned to a cache line. With 32- and 64-byte vectors (AVX2, AVX-512: a -DNONSEP_NATIVE=ON build), an array that
// malloc places at 16 bytes past a cache line makes every other or every vector load and store straddle two lines:
// measured on this project's AMD EPYC (Zen 4) VM, the stage-by-stage loop over 256 states of paper1d took 2.78 ns per
// state and step on such arrays and 2.22 ns on aligned ones. Portable (SSE2) code loses nothing either way.
#include <cstddef>
#include <new>
#include <vector>

namespace nonsep {

inline constexpr std::size_t cache_line_size = 64;

// A std::allocator whose blocks start on a cache line.
template <class T>
struct CacheLineAllocator {
  using value_type = T;

  CacheLineAllocator() = default;
  template <class U>
  CacheLineAllocator(const CacheLineAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(cache_line_size)));
  }
  void deallocate(T* pointer, std::size_t) noexcept { ::operator delete(pointer, std::align_val_t(cache_line_size)); }

  template <class U>
  friend bool operator==(const CacheLineAllocator&, const CacheLineAllocator<U>&) noexcept {
    return true;
  }
};

// A vector of doubles that starts on a cache line.
using AlignedDoubles = std::vector<double, CacheLineAllocator<double>>;

}  // namespace nonsep
