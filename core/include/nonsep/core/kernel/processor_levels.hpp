#pragma once
// Whether this processor runs code compiled for an x86-64 micro-architecture level: the one rule behind the host's
// choice of a plugin's stepping kernels (host/loader/src/kernel_choice.cpp) and the SDK's choice of its Gauss-Legendre
// kernel's wider copy (nonsep/sdk/kernels.hpp), which a plugin makes without the host.
#include <string_view>

namespace nonsep {

// The level of an instruction set's name as the plugins' metadata writes it: "x86-64" (the baseline) 1,
// "x86-64-v3" 3, "x86-64-v4" 4; 0 for another name.
constexpr int processor_level(std::string_view name) {
  return name == "x86-64" ? 1 : name == "x86-64-v3" ? 3 : name == "x86-64-v4" ? 4 : 0;
}

// Level 1 always (the name of the baseline of every build); 3 (AVX2, FMA, BMI1, BMI2) and 4 (those and AVX-512 F, BW,
// CD, DQ, VL) when the processor has them; false for another level and off x86-64. GCC 12 and later ask for the level
// by name; clang and GCC 11 know features, not levels: the levels' vector and bit-manipulation features.
inline bool processor_runs_level(int level) {
  if (level == 1) return true;
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init();
#if !defined(__clang__) && __GNUC__ >= 12
  if (level == 3) return __builtin_cpu_supports("x86-64-v3");
  if (level == 4) return __builtin_cpu_supports("x86-64-v4");
#else
  const bool v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
                  __builtin_cpu_supports("bmi2");
  if (level == 3) return v3;
  if (level == 4)
    return v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
           __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512dq") &&
           __builtin_cpu_supports("avx512vl");
#endif
#endif
  return false;
}

}  // namespace nonsep
