#pragma once
// The stepping kernels an SDK plugin carries (plugin_abi.h, chin_steps and chin_tangent_steps):
// nonsep::chin_kernel_blocks and nonsep::chin_tangent_kernel_blocks, the core's own templates
// (nonsep/core/kernel/chin_kernel.hpp), instantiated with the plugin's model adapter inlined. No stepping code is
// written here: this header only compiles that template once per instruction set and picks one by index.
//
// Instruction sets, in the order of the metadata's "kernels": {"instruction_sets": [...]} (index 0 first):
//   "x86-64"     the baseline every x86-64 runs, compiled with the plugin's own flags: bit for bit the evaluation
//                path of a host built with the same flags
//   "x86-64-v3"  AVX2 and FMA (GCC's target attribute "arch=x86-64-v3")
//   "x86-64-v4"  AVX-512 (F, BW, CD, DQ, VL)
// The wider sets run more numbers per instruction and fuse multiplications and additions (one rounding instead of
// two), so their numbers may differ from the baseline's in the last bits (docs/performance.md measures by how
// much). The host chooses the set from the processor's features, or the one NONSEP_INSTRUCTION_SET names.
// Each wider instantiation is flattened (every call inside inlined), so that the model's code is compiled for the
// wider set too and not called in its baseline copy. Other processors (and compilers without the attribute) get
// the baseline alone, and so does a plugin compiled for a processor already (-march=native, NONSEP_NATIVE: __AVX__
// defined): its baseline uses that processor's vectors, and GCC inlines nothing compiled for one processor into a
// function of another arch, so a wider kernel there would call the model's gradients out of line.
// NONSEP_SDK_WIDE_KERNEL_SETS (default 3) chooses the wider sets compiled, as bits: 1 for x86-64-v3, 2 for x86-64-v4, 0
// for none (each costs compile time; formula models compile the one the host uses). NONSEP_SDK_BASELINE_KERNELS 0
// leaves the baseline kernels out when a wider set is compiled (nonsep_add_model's default, KERNEL_SETS native, and a
// formula model's cached plugin: built for the machine that compiles them, where the host takes the wider set; the
// baseline Chin kernels are about a third of a plugin's compile time); the metadata then names the wider set alone,
// NONSEP_INSTRUCTION_SET=x86-64 is refused for such a plugin (a formula model compiles a plugin of its own), and a
// processor that runs none of its sets steps it through the evaluation path.
//
// Kernel units: the wider sets' kernels may be compiled in translation units of their own, in parallel with the rest
// of the plugin (nonsep_add_model does so for a one-file plugin; the plugin is the same, built in about half the wall
// time on two cores: docs/writing-models.md). NONSEP_SDK_KERNEL_UNIT says what a translation unit compiles:
//   0 (default)  the plugin: its table, the baseline kernels, and the wider kernels not in units of their own
//                (NONSEP_SDK_SEPARATE_KERNEL_UNITS, bits as above: those are declared here and called)
//   1, 2         the x86-64-v3 (1) or x86-64-v4 (2) kernels alone: NONSEP_EXPORT_MODEL expands to the definition of
//                nonsep::sdk::kernel_unit_1 (_2) and nothing else
// The units see the same source, so the adapter they step is the plugin's (the function takes it as const void*).
//
// The Gauss-Legendre kernel (plugin_abi.h gauss_steps, GaussKernels below) has no instruction set to choose: every
// copy of it gives the evaluation path's numbers. It is compiled with the plugin's own flags and, for a model that
// writes out every derivative grad H needs (its kernel flattened), also for the widest set of
// NONSEP_SDK_WIDE_KERNEL_SETS (in that set's kernel unit where it has one), that copy without fused multiply-adds
// (GCC's optimize attribute, fp-contract=off): with the SDK's flags (no -ffast-math, so no reassociation either)
// vectors across a block's states round every operation as the baseline's scalars do, and the copy the processor runs
// changes the speed alone (paper2d's 1024 orbits, gauss 3, 2000 steps: 0.72 s against 0.93 s of CPU on AVX-512). The
// plugin takes the wider copy where the processor runs it, else the baseline one; NONSEP_INSTRUCTION_SET pins the Chin
// kernels, not this.
#include <cstddef>
#include <span>
#include <string_view>

#include "nonsep/core/kernel/chin_kernel.hpp"
#include "nonsep/core/kernel/gauss_stages.hpp"
#include "nonsep/core/kernel/processor_levels.hpp"
#include "nonsep/sdk/model_adapter.hpp"

namespace nonsep::sdk {

#ifndef NONSEP_SDK_WIDE_KERNEL_SETS
#define NONSEP_SDK_WIDE_KERNEL_SETS 3
#endif
#ifndef NONSEP_SDK_KERNEL_UNIT
#define NONSEP_SDK_KERNEL_UNIT 0
#endif
#ifndef NONSEP_SDK_SEPARATE_KERNEL_UNITS
#define NONSEP_SDK_SEPARATE_KERNEL_UNITS 0
#endif
// Whether the plugin carries the tangent kernels (chin_tangent_steps): 1 when built by nonsep_add_model(...
// TANGENT_KERNELS). They make a Lyapunov, MEGNO, SALI or GALI run of a Chin scheme about as fast as a hand-written
// tangent step, and cost their compile time: radial's plugin builds in 12 s of wall time on two idle cores without
// them and 71 s with them (docs/writing-models.md). Without them the host steps tangent vectors through the
// evaluation path.
#ifndef NONSEP_SDK_TANGENT_KERNELS
#define NONSEP_SDK_TANGENT_KERNELS 0
#endif
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__AVX__)
#define NONSEP_SDK_KERNEL_V3 \
  (NONSEP_SDK_KERNEL_UNIT == 0 ? (NONSEP_SDK_WIDE_KERNEL_SETS & 1) : NONSEP_SDK_KERNEL_UNIT == 1)
#define NONSEP_SDK_KERNEL_V4 \
  (NONSEP_SDK_KERNEL_UNIT == 0 ? (NONSEP_SDK_WIDE_KERNEL_SETS & 2) : NONSEP_SDK_KERNEL_UNIT == 2)
#else
#define NONSEP_SDK_KERNEL_V3 0
#define NONSEP_SDK_KERNEL_V4 0
#endif
#ifndef NONSEP_SDK_BASELINE_KERNELS
#define NONSEP_SDK_BASELINE_KERNELS 1
#endif
// Whether the plugin has the baseline kernels: unless left out, and always when it has no wider set.
#define NONSEP_SDK_KERNEL_BASELINE (NONSEP_SDK_BASELINE_KERNELS || !(NONSEP_SDK_KERNEL_V3 || NONSEP_SDK_KERNEL_V4))
// Whether this unit compiles the kernel bodies of v3 (v4), or calls another unit's.
#define NONSEP_SDK_KERNEL_V3_HERE (NONSEP_SDK_KERNEL_V3 && !(NONSEP_SDK_SEPARATE_KERNEL_UNITS & 1))
#define NONSEP_SDK_KERNEL_V4_HERE (NONSEP_SDK_KERNEL_V4 && !(NONSEP_SDK_SEPARATE_KERNEL_UNITS & 2))
// The kernels of units 1 and 2, defined by NONSEP_SDK_DEFINE_KERNEL_UNIT there: the steps, and the tangent steps.
void kernel_unit_1(const void* adapter, const ChinStepsCall& call);
void kernel_unit_2(const void* adapter, const ChinStepsCall& call);
void tangent_kernel_unit_1(const void* adapter, const ChinTangentStepsCall& call);
void tangent_kernel_unit_2(const void* adapter, const ChinTangentStepsCall& call);
inline constexpr std::string_view kernel_instruction_sets[] = {
#if NONSEP_SDK_KERNEL_BASELINE
    "x86-64",
#endif
#if NONSEP_SDK_KERNEL_V3
    "x86-64-v3",
#endif
#if NONSEP_SDK_KERNEL_V4
    "x86-64-v4",
#endif
};

// The kernels of one adapter type: run(index, adapter, call) advances call by the kernel of instruction set
// `index` (an index into kernel_instruction_sets; false when out of range). Throws what the model throws.
template <class Adapter>
struct ChinKernels {
  static constexpr std::size_t fixed_dimension =
      HasFixedDimension<typename Adapter::Model> ? dimension_capacity<typename Adapter::Model>() : 0;

  // Each instruction set's kernel twice: for basic steps and for expansions (ChinStepsCall::weights), separate
  // functions, so that the code of one does not shape the other's (registers, stack frame, layout: the basic steps of
  // 1024 states ran 15% slower when both were one function).
  template <bool Expansion>
  [[gnu::flatten]] static void baseline(const Adapter& adapter, const ChinStepsCall& call) {
    chin_kernel_blocks<fixed_dimension, Expansion>(adapter, call);
  }
#if NONSEP_SDK_KERNEL_V3_HERE
  template <bool Expansion>
  [[gnu::target("arch=x86-64-v3"), gnu::flatten]] static void v3(const Adapter& adapter, const ChinStepsCall& call) {
    chin_kernel_blocks<fixed_dimension, Expansion>(adapter, call);
  }
#endif
#if NONSEP_SDK_KERNEL_V4_HERE
  template <bool Expansion>
  [[gnu::target("arch=x86-64-v4"), gnu::flatten]] static void v4(const Adapter& adapter, const ChinStepsCall& call) {
    chin_kernel_blocks<fixed_dimension, Expansion>(adapter, call);
  }
#endif

#if NONSEP_SDK_TANGENT_KERNELS
  // The tangent kernels (chin_tangent_kernel_blocks), one per instruction set as above.
  [[gnu::flatten]] static void tangent_baseline(const Adapter& adapter, const ChinTangentStepsCall& call) {
    chin_tangent_kernel_blocks<fixed_dimension>(adapter, call);
  }
#if NONSEP_SDK_KERNEL_V3_HERE
  [[gnu::target("arch=x86-64-v3"), gnu::flatten]] static void tangent_v3(const Adapter& adapter,
                                                                         const ChinTangentStepsCall& call) {
    chin_tangent_kernel_blocks<fixed_dimension>(adapter, call);
  }
#endif
#if NONSEP_SDK_KERNEL_V4_HERE
  [[gnu::target("arch=x86-64-v4"), gnu::flatten]] static void tangent_v4(const Adapter& adapter,
                                                                         const ChinTangentStepsCall& call) {
    chin_tangent_kernel_blocks<fixed_dimension>(adapter, call);
  }
#endif

#endif

  // As run, for a tangent call; false for every set when the plugin carries no tangent kernels.
  static bool run_tangent([[maybe_unused]] std::size_t index, [[maybe_unused]] const Adapter& adapter,
                          [[maybe_unused]] const ChinTangentStepsCall& call) {
#if !NONSEP_SDK_TANGENT_KERNELS
    return false;
#else
    std::size_t set = 0;
#if NONSEP_SDK_KERNEL_BASELINE
    if (index == set++) {
      tangent_baseline(adapter, call);
      return true;
    }
#endif
#if NONSEP_SDK_KERNEL_V3
    if (index == set++) {
#if NONSEP_SDK_KERNEL_V3_HERE
      tangent_v3(adapter, call);
#else
      tangent_kernel_unit_1(&adapter, call);
#endif
      return true;
    }
#endif
#if NONSEP_SDK_KERNEL_V4
    if (index == set++) {
#if NONSEP_SDK_KERNEL_V4_HERE
      tangent_v4(adapter, call);
#else
      tangent_kernel_unit_2(&adapter, call);
#endif
      return true;
    }
#endif
    return false;
#endif
  }

  static bool run(std::size_t index, const Adapter& adapter, const ChinStepsCall& call) {
    [[maybe_unused]] const bool expansion = !call.weights.empty();  // unused when every set is in a unit of its own
    std::size_t set = 0;
#if NONSEP_SDK_KERNEL_BASELINE
    if (index == set++) {
      expansion ? baseline<true>(adapter, call) : baseline<false>(adapter, call);
      return true;
    }
#endif
#if NONSEP_SDK_KERNEL_V3
    if (index == set++) {
#if NONSEP_SDK_KERNEL_V3_HERE
      expansion ? v3<true>(adapter, call) : v3<false>(adapter, call);
#else
      kernel_unit_1(&adapter, call);
#endif
      return true;
    }
#endif
#if NONSEP_SDK_KERNEL_V4
    if (index == set++) {
#if NONSEP_SDK_KERNEL_V4_HERE
      expansion ? v4<true>(adapter, call) : v4<false>(adapter, call);
#else
      kernel_unit_2(&adapter, call);
#endif
      return true;
    }
#endif
    return false;
  }

#if NONSEP_SDK_KERNEL_UNIT == 1 && NONSEP_SDK_KERNEL_V3
  static void run_unit(const Adapter& adapter, const ChinStepsCall& call) {
    !call.weights.empty() ? v3<true>(adapter, call) : v3<false>(adapter, call);
  }
#if NONSEP_SDK_TANGENT_KERNELS
  static void run_tangent_unit(const Adapter& adapter, const ChinTangentStepsCall& call) { tangent_v3(adapter, call); }
#endif
#elif NONSEP_SDK_KERNEL_UNIT == 2 && NONSEP_SDK_KERNEL_V4
  static void run_unit(const Adapter& adapter, const ChinStepsCall& call) {
    !call.weights.empty() ? v4<true>(adapter, call) : v4<false>(adapter, call);
  }
#if NONSEP_SDK_TANGENT_KERNELS
  static void run_tangent_unit(const Adapter& adapter, const ChinTangentStepsCall& call) { tangent_v4(adapter, call); }
#endif
#endif
};

// The Gauss-Legendre kernel's wider copy (GaussKernels below): for the widest set the plugin's Chin kernels are
// compiled for, x86-64-v4 (unit 2) or x86-64-v3 (unit 1), 0 for none; compiled in that set's kernel unit where it has
// one of its own (NONSEP_SDK_SEPARATE_KERNEL_UNITS), else here.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__AVX__)
#define NONSEP_SDK_GAUSS_WIDE_UNIT ((NONSEP_SDK_WIDE_KERNEL_SETS & 2) ? 2 : (NONSEP_SDK_WIDE_KERNEL_SETS & 1) ? 1 : 0)
#else
#define NONSEP_SDK_GAUSS_WIDE_UNIT 0
#endif
#define NONSEP_SDK_GAUSS_WIDE_HERE                                                                 \
  (NONSEP_SDK_GAUSS_WIDE_UNIT != 0 &&                                                              \
   (NONSEP_SDK_KERNEL_UNIT == 0 ? !(NONSEP_SDK_SEPARATE_KERNEL_UNITS & NONSEP_SDK_GAUSS_WIDE_UNIT) \
                                : NONSEP_SDK_KERNEL_UNIT == NONSEP_SDK_GAUSS_WIDE_UNIT))
#if NONSEP_SDK_GAUSS_WIDE_UNIT == 2
#define NONSEP_SDK_GAUSS_WIDE_TARGET "arch=x86-64-v4"
#elif NONSEP_SDK_GAUSS_WIDE_UNIT == 1
#define NONSEP_SDK_GAUSS_WIDE_TARGET "arch=x86-64-v3"
#endif
void gauss_kernel_unit_1(const void* adapter, const GaussStepsCall& call);
void gauss_kernel_unit_2(const void* adapter, const GaussStepsCall& call);

// The Gauss-Legendre kernel of one adapter type (above): run(adapter, call) takes call's step. A model that writes out
// every derivative grad H needs gets the iteration flattened (the derivatives inlined into it) and the wider copy;
// one differentiated automatically does not, since the inlined dual-number code multiplies the plugin's compile time
// (radial: 15 s -> 70 s). A plugin without the baseline kernels (KERNEL_SETS native, a formula model's cached plugin)
// keeps the baseline copy for a processor that does not run its wider set, not flattened, so that it compiles one
// flattened kernel, the wider one.
template <class Adapter>
struct GaussKernels {
  static constexpr bool gradient_written_out = [] {
    if constexpr (requires { Adapter::analytic_grad_H; })
      return Adapter::analytic_grad_H;
    else
      return Adapter::analytic_grad_T && Adapter::analytic_grad_V && Adapter::analytic_hvp_T &&
             Adapter::analytic_hvp_V && Adapter::analytic_d3T && Adapter::analytic_d3V;
  }();
  static constexpr std::size_t fixed_dimension =
      HasFixedDimension<typename Adapter::Model> ? dimension_capacity<typename Adapter::Model>() : 0;

  static void run(const Adapter& adapter, const GaussStepsCall& call) {
    if constexpr (!gradient_written_out)
      gauss_kernel_steps<fixed_dimension>(adapter, call);
    else if (processor_runs_wide())
      wide(adapter, call);
    else
      baseline(adapter, call);
  }
  // The wider copy, where a kernel unit calls it (gauss_kernel_unit_1, _2): nothing for a model whose kernel is not
  // flattened, which never calls it.
  static void run_wide_unit([[maybe_unused]] const Adapter& adapter, [[maybe_unused]] const GaussStepsCall& call) {
#if NONSEP_SDK_GAUSS_WIDE_HERE
    if constexpr (gradient_written_out) flat_wide(adapter, call);
#endif
  }

 private:
  static void baseline(const Adapter& adapter, const GaussStepsCall& call) {
#if NONSEP_SDK_KERNEL_BASELINE
    flat(adapter, call);
#else
    gauss_kernel_steps<fixed_dimension>(adapter, call);
#endif
  }
  [[gnu::flatten]] static void flat(const Adapter& adapter, const GaussStepsCall& call) {
    gauss_kernel_steps<fixed_dimension>(adapter, call);
  }
#if NONSEP_SDK_GAUSS_WIDE_HERE
  [[gnu::target(NONSEP_SDK_GAUSS_WIDE_TARGET), gnu::optimize("fp-contract=off"), gnu::flatten]] static void flat_wide(
      const Adapter& adapter, const GaussStepsCall& call) {
    gauss_kernel_steps<fixed_dimension>(adapter, call);
  }
#endif
  static void wide(const Adapter& adapter, const GaussStepsCall& call) {
#if NONSEP_SDK_GAUSS_WIDE_UNIT == 0
    baseline(adapter, call);  // not reached: the processor runs no wider copy
#elif NONSEP_SDK_GAUSS_WIDE_HERE
    flat_wide(adapter, call);
#elif NONSEP_SDK_GAUSS_WIDE_UNIT == 1
    gauss_kernel_unit_1(&adapter, call);
#else
    gauss_kernel_unit_2(&adapter, call);
#endif
  }
  // Whether this processor runs the wider copy, found once.
  static bool processor_runs_wide() {
#if NONSEP_SDK_GAUSS_WIDE_UNIT == 0
    return false;
#else
    static const bool runs = processor_runs_level(NONSEP_SDK_GAUSS_WIDE_UNIT == 2 ? 4 : 3);
    return runs;
#endif
  }
};

}  // namespace nonsep::sdk

// A kernel unit's definitions (NONSEP_EXPORT_MODEL in a unit 1 or 2), or nothing where that set is not compiled.
#if NONSEP_SDK_KERNEL_UNIT != 0 && (NONSEP_SDK_KERNEL_V3 || NONSEP_SDK_KERNEL_V4)
#define NONSEP_SDK_KERNEL_UNIT_FUNCTION_OF(prefix, unit) ::nonsep::sdk::prefix##kernel_unit_##unit
#define NONSEP_SDK_KERNEL_UNIT_FUNCTION(prefix, unit) NONSEP_SDK_KERNEL_UNIT_FUNCTION_OF(prefix, unit)
#define NONSEP_SDK_DEFINE_KERNEL_UNIT(...)                                                              \
  void NONSEP_SDK_KERNEL_UNIT_FUNCTION(, NONSEP_SDK_KERNEL_UNIT)(const void* adapter,                   \
                                                                 const ::nonsep::ChinStepsCall& call) { \
    ::nonsep::sdk::ChinKernels<__VA_ARGS__>::run_unit(*static_cast<const __VA_ARGS__*>(adapter), call); \
  }                                                                                                     \
  NONSEP_SDK_DEFINE_TANGENT_KERNEL_UNIT(__VA_ARGS__)                                                    \
  NONSEP_SDK_DEFINE_GAUSS_KERNEL_UNIT(__VA_ARGS__)
#if NONSEP_SDK_KERNEL_UNIT == NONSEP_SDK_GAUSS_WIDE_UNIT
#define NONSEP_SDK_DEFINE_GAUSS_KERNEL_UNIT(...)                                                               \
  void NONSEP_SDK_KERNEL_UNIT_FUNCTION(gauss_, NONSEP_SDK_KERNEL_UNIT)(const void* adapter,                    \
                                                                       const ::nonsep::GaussStepsCall& call) { \
    ::nonsep::sdk::GaussKernels<__VA_ARGS__>::run_wide_unit(*static_cast<const __VA_ARGS__*>(adapter), call);  \
  }
#else
#define NONSEP_SDK_DEFINE_GAUSS_KERNEL_UNIT(...)
#endif
#if NONSEP_SDK_TANGENT_KERNELS
#define NONSEP_SDK_DEFINE_TANGENT_KERNEL_UNIT(...)                                                                     \
  void NONSEP_SDK_KERNEL_UNIT_FUNCTION(tangent_, NONSEP_SDK_KERNEL_UNIT)(const void* adapter,                          \
                                                                         const ::nonsep::ChinTangentStepsCall& call) { \
    ::nonsep::sdk::ChinKernels<__VA_ARGS__>::run_tangent_unit(*static_cast<const __VA_ARGS__*>(adapter), call);        \
  }
#else
#define NONSEP_SDK_DEFINE_TANGENT_KERNEL_UNIT(...)
#endif
#else
#define NONSEP_SDK_DEFINE_KERNEL_UNIT(...)
#endif
