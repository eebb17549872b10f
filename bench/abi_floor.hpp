#pragma once
// The floor of an evaluation-only plugin boundary (bench/performance.cpp, figures 1a and 2a): the hand-written loops
// of hand_written.hpp with each gradient a call of a plugin's table (plugin_abi.h) instead of inline code. The
// plugin is paper1d_minimal.so (paper1d_minimal.cpp: no SDK, no checks), the loop has no Integrator, no batch types
// and no host, and it checks each call's status as any host must. What this costs over hand_written.hpp is the
// price of the boundary itself: the numbers go to the plugin and come back through memory (a gradient is written
// into an array by the plugin and read back by the flow), which a host of version 3 of the ABI cannot avoid. What a
// host costs over this floor is the host's own.
//
// The control (figure 1r): the same loop for one trajectory calling paper1d_minimal's scalar functions through
// function pointers, one number in and out by value (registers): a call that passes nothing through memory.
#include <dlfcn.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "hand_written.hpp"
#include "nonsep/core/base/aligned_allocator.hpp"
#include "nonsep/plugin_abi.h"

namespace bench {

// paper1d_minimal.so, loaded with dlopen (not with nonsep's loader: nothing of the host takes part).
class MinimalPlugin {
 public:
  using Scalar = double (*)(double);

  explicit MinimalPlugin(const std::string& path) : library_(::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) {
    if (library_ == nullptr) throw std::runtime_error("cannot load " + path + ": " + ::dlerror());
    const auto* pointer = static_cast<const nonsep_plugin_api* const*>(::dlsym(library_, NONSEP_PLUGIN_SYMBOL));
    grad_T_scalar = reinterpret_cast<Scalar>(::dlsym(library_, "paper1d_minimal_grad_T_scalar"));
    grad_V_scalar = reinterpret_cast<Scalar>(::dlsym(library_, "paper1d_minimal_grad_V_scalar"));
    if (pointer == nullptr || grad_T_scalar == nullptr || grad_V_scalar == nullptr)
      throw std::runtime_error(path + " lacks the symbols of paper1d_minimal.cpp");
    api = *pointer;
    if (api->create("{}", &instance, nullptr, 0) != NONSEP_OK) throw std::runtime_error("create failed");
  }
  ~MinimalPlugin() {
    api->destroy(instance);
    ::dlclose(library_);
  }
  MinimalPlugin(const MinimalPlugin&) = delete;
  MinimalPlugin& operator=(const MinimalPlugin&) = delete;

  const nonsep_plugin_api* api = nullptr;
  nonsep_instance* instance = nullptr;
  Scalar grad_T_scalar = nullptr, grad_V_scalar = nullptr;

 private:
  void* library_;
};

[[noreturn, gnu::cold, gnu::noinline]] inline void throw_plugin_failed() {
  throw std::runtime_error("paper1d_minimal failed");
}

// `steps` basic steps of `count` trajectories q[b], p[b], in place, stage by stage with the plugin's gradients:
// grad V into g (count entries), grad T into t (count entries). One state is the single-trajectory floor.
inline void abi_floor_run(const HandWrittenStep& c, const MinimalPlugin& plugin, double* q, double* p, double* g,
                          double* t, std::size_t count, std::uint64_t steps) {
  const nonsep_plugin_api& api = *plugin.api;
  nonsep_instance* instance = plugin.instance;
  const auto evaluate = [&](auto function, const double* at, double* out) {
    if (function(instance, at, out, count) != NONSEP_OK) [[unlikely]]
      throw_plugin_failed();
  };
  // One state takes a scalar statement: a loop of unknown length is versioned for vectorization, and its alias
  // checks and prologue are not part of the floor.
  const auto flow = [count](double* y, const double* gradient, double h) {
    if (count == 1) {
      y[0] += h * gradient[0];
      return;
    }
    for (std::size_t b = 0; b < count; ++b) y[b] += h * gradient[b];
  };
  const auto kick = [&](double h) { flow(p, g, h); };
  const auto drift = [&](double h) {
    evaluate(api.grad_T, p, t);
    flow(q, t, h);
    evaluate(api.grad_V, q, g);
  };
  evaluate(api.grad_V, q, g);
  for (std::uint64_t k = 0; k < steps; ++k) basic_step_stages(c, kick, drift);
}

// The same in the host's blocks of `block` states, each stepped to the end in turn (one thread), as the host's
// driver does with its blocks.
inline void abi_floor_run_blocks(const HandWrittenStep& c, const MinimalPlugin& plugin, nonsep::AlignedDoubles& q,
                                 nonsep::AlignedDoubles& p, std::size_t block, std::uint64_t steps) {
  nonsep::AlignedDoubles g(q.size()), t(q.size());
  for (std::size_t first = 0; first < q.size(); first += block) {
    const std::size_t size = std::min(block, q.size() - first);
    abi_floor_run(c, plugin, q.data() + first, p.data() + first, g.data() + first, t.data() + first, size, steps);
  }
}

// The control: one trajectory, the gradients called through function pointers by value.
inline void register_call_run(const HandWrittenStep& c, const MinimalPlugin& plugin, double& q, double& p,
                              std::uint64_t steps) {
  hand_written_run(c, q, p, steps, plugin.grad_T_scalar, plugin.grad_V_scalar);
}

}  // namespace bench
