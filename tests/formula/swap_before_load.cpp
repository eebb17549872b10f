// Preloaded into nonsep (LD_PRELOAD) by test_formula_cache_safety.cpp to act out another user swapping a formula
// cache entry between its check and its load: the first dlopen of NONSEP_TEST_SWAP_TO, or of a file held open
// (/proc/self/fd/N), first renames NONSEP_TEST_SWAP_FROM over NONSEP_TEST_SWAP_TO, then loads what it was asked.
#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

extern "C" __attribute__((visibility("default"))) void* dlopen(const char* file, int mode) {
  using Dlopen = void* (*)(const char*, int);
  static const auto real = reinterpret_cast<Dlopen>(dlsym(RTLD_NEXT, "dlopen"));
  static bool swapped = false;
  const char* from = std::getenv("NONSEP_TEST_SWAP_FROM");
  const char* to = std::getenv("NONSEP_TEST_SWAP_TO");
  if (!swapped && file && from && to && (std::strcmp(file, to) == 0 || std::strncmp(file, "/proc/self/fd/", 14) == 0)) {
    swapped = true;
    std::rename(from, to);
  }
  return real(file, mode);
}
