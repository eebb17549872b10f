// The cost of following tangent vectors (docs/performance-tangent.md): time per basic step of
// TangentBasicStep with k tangent vectors per trajectory over the plain ChinBasicStep, same model, same states, in
// the same run. k = 1 (largest Lyapunov exponent, MEGNO) and k = 2n (the whole spectrum), on paper1d and paper2d
// compiled in (the shipped model classes through ModelAdapter: analytic gradients, Hessians by the SDK's
// automatic differentiation, as their plugins evaluate them), one batch of 1024 trajectories, dt = 1e-4.
// Configurations are interleaved; each figure is the median over the repetitions of (time with tangents) /
// (time plain) in the same repetition, with the lowest and highest ratio as the spread. Each run's final states
// are checked bit for bit against the plain stepper's, so a faster but different path cannot pass.
//
// Usage: nonsep_bench_tangent_map [--smoke] [--repetitions N] [--steps S]
//   --smoke         3 repetitions of 200 steps (the ctest bench.tangent_map.smoke)
//   --repetitions   default 7;   --steps   basic steps per run, default 2000
// Exit status 1 when the states stepped with tangents differ from the plain ones.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "nonsep/core/schemes/chin_basic_step.hpp"
#include "nonsep/core/tangent/tangent_basic_step.hpp"
#include "paper1d/paper1d.hpp"
#include "paper2d/paper2d.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t m = values.size() / 2;
  return values.size() % 2 ? values[m] : 0.5 * (values[m - 1] + values[m]);
}

// States spread over a box (q in [-1, 1], p in [-0.5, 0.5]), the same for every configuration.
nonsep::PhaseSpaceBatch initial_states(std::size_t n, std::size_t count) {
  nonsep::PhaseSpaceBatch x(n, count);
  for (std::size_t i = 0; i < x.size(); ++i) {
    x.q()[i] = -1.0 + 2.0 * static_cast<double>((i * 37) % 101) / 100.0;
    x.p()[i] = -0.5 + static_cast<double>((i * 53) % 97) / 96.0;
  }
  return x;
}

struct Timing {
  double seconds;
  nonsep::PhaseSpaceBatch final_states;
};

template <class M>
Timing time_plain(const M& model, std::size_t count, std::uint64_t steps, double dt) {
  auto x = initial_states(model.dimension(), count);
  nonsep::ChinBasicStep stepper;
  const auto start = Clock::now();
  for (std::uint64_t s = 0; s < steps; ++s) stepper.step(model, x, dt);
  return {std::chrono::duration<double>(Clock::now() - start).count(), x};
}

template <class M>
Timing time_tangent(const M& model, std::size_t count, std::size_t k, std::uint64_t steps, double dt) {
  const std::size_t n = model.dimension();
  auto x = initial_states(n, count);
  nonsep::PhaseSpaceBatch tangents(n, count * k);
  for (std::size_t v = 0; v < count * k; ++v) tangents.q(v)[v % n] = 1.0;
  nonsep::TangentBasicStep stepper;
  const auto start = Clock::now();
  for (std::uint64_t s = 0; s < steps; ++s) stepper.step(model, x, tangents, dt);
  return {std::chrono::duration<double>(Clock::now() - start).count(), x};
}

// Prints the ratios for k = 1 and k = 2n on `model`; returns false if a run's states differ from the plain run.
template <class M>
bool measure(const char* name, const M& model, int repetitions, std::uint64_t steps, double dt) {
  const std::size_t count = 1024, n = model.dimension();
  std::vector<double> plain_ns, ratio_1, ratio_2n;
  bool identical = true;
  for (int r = 0; r < repetitions; ++r) {
    const Timing plain = time_plain(model, count, steps, dt);
    const Timing one = time_tangent(model, count, 1, steps, dt);
    const Timing all = time_tangent(model, count, 2 * n, steps, dt);
    identical = identical && one.final_states == plain.final_states && all.final_states == plain.final_states;
    plain_ns.push_back(plain.seconds / static_cast<double>(steps * count) * 1e9);
    ratio_1.push_back(one.seconds / plain.seconds);
    ratio_2n.push_back(all.seconds / plain.seconds);
  }
  const auto [low_1, high_1] = std::minmax_element(ratio_1.begin(), ratio_1.end());
  const auto [low_2n, high_2n] = std::minmax_element(ratio_2n.begin(), ratio_2n.end());
  std::printf(
      "%-8s plain %6.1f ns per basic step per trajectory | k = 1: %5.2fx [%4.2f, %4.2f] | k = %zu: %5.2fx "
      "[%4.2f, %4.2f]%s\n",
      name, median(plain_ns), median(ratio_1), *low_1, *high_1, 2 * n, median(ratio_2n), *low_2n, *high_2n,
      identical ? "" : "  STATES DIFFER");
  return identical;
}

}  // namespace

int main(int argc, char** argv) {
  int repetitions = 7;
  std::uint64_t steps = 2000;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "--smoke") {
      repetitions = 3;
      steps = 200;
    } else if (argument == "--repetitions" && i + 1 < argc) {
      repetitions = std::atoi(argv[++i]);
    } else if (argument == "--steps" && i + 1 < argc) {
      steps = std::strtoull(argv[++i], nullptr, 10);
    } else {
      std::fprintf(stderr, "usage: nonsep_bench_tangent_map [--smoke] [--repetitions N] [--steps S]\n");
      return 2;
    }
  }
  // dt from the environment's view, not a literal: the compiler would fold cbrt(1e-4) correctly rounded, which
  // can differ in the last bit from the run-time cbrt.
  volatile double opaque_dt = 1e-4;
  const double dt = opaque_dt;
  std::printf(
      "tangent map cost, 1024 trajectories, basic step, dt = 1e-4, %d repetitions of %llu steps "
      "(median ratio [lowest, highest])\n",
      repetitions, static_cast<unsigned long long>(steps));
  const nonsep::sdk::ModelAdapter<Paper1D> paper1d;
  const auto paper2d = nonsep::sdk::ModelAdapter<Paper2D>::from_json("{}");
  bool identical = measure("paper1d", paper1d, repetitions, steps, dt);
  identical = measure("paper2d", paper2d, repetitions, steps, dt) && identical;
  return identical ? 0 : 1;
}
