// What the plugin boundary and automatic differentiation cost: basic steps (Chin's eq. expalg, 4 grad T + 4 grad V
// per step) per second on paper1d,
//   compiled in, analytic gradients    nonsep::sdk::ModelAdapter<Paper1D>            (the reference)
//   plugin,      analytic gradients    paper1d.so through nonsep::host::PluginModel
//   compiled in, AD gradients          ModelAdapter<Paper1D, Derivatives::automatic>
//   plugin,      AD gradients          paper1d_autodiff.so
// for batches of 1, 64 and 4096 states (the boundary is crossed once per batch). Every configuration is measured
// in the same run, interleaved, `repetitions` times; the median is reported, and the ratios to the reference.
//
// Usage: nonsep_bench_plugin_overhead [repetitions (default 9)] [state-steps per measurement (default 2^21)]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "nonsep/core/schemes/chin_basic_step.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "paper1d/paper1d.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// Initial states: q spread over [0.2, 1.8], p = 0 (closed orbits of the paper's Fig. 1).
nonsep::PhaseSpaceBatch initial_states(std::size_t count) {
  nonsep::PhaseSpaceBatch x(1, count);
  for (std::size_t b = 0; b < count; ++b) x.q()[b] = 0.2 + 1.6 * static_cast<double>(b) / static_cast<double>(count);
  return x;
}

// Seconds for `steps` basic steps of a batch of `count` states; `checksum` receives q of the first state.
template <class Model>
double time_steps(const Model& model, std::size_t count, std::size_t steps, double& checksum) {
  auto x = initial_states(count);
  nonsep::ChinBasicStep stepper;
  const auto start = Clock::now();
  for (std::size_t k = 0; k < steps; ++k) stepper.step(model, x, 1e-3);
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  checksum = x.q()[0];
  return elapsed.count();
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t m = values.size() / 2;
  return values.size() % 2 ? values[m] : 0.5 * (values[m - 1] + values[m]);
}

struct Configuration {
  const char* name;
  std::function<double(std::size_t count, std::size_t steps, double& checksum)> run;
  std::vector<double> steps_per_second{};
  double checksum = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  const int repetitions = argc > 1 ? std::max(1, std::atoi(argv[1])) : 9;
  const std::size_t state_steps = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : (std::size_t{1} << 21);

  const nonsep::sdk::ModelAdapter<Paper1D> compiled_analytic;
  const nonsep::sdk::ModelAdapter<Paper1D, nonsep::sdk::Derivatives::automatic> compiled_automatic;
  const auto plugin_analytic =
      nonsep::host::load_plugin(std::string(NONSEP_BUILD_PLUGIN_DIR) + "/paper1d.so", "").create({});
  const auto plugin_automatic =
      nonsep::host::load_plugin(std::string(NONSEP_BENCH_PLUGIN_DIR) + "/paper1d_autodiff.so", "").create({});

  std::printf("basic steps of paper1d (dt = 1e-3), median of %d repetitions, %zu state-steps each\n", repetitions,
              state_steps);
  std::printf("%-8s %-34s %16s %12s\n", "batch", "configuration", "state-steps/s", "vs reference");
  for (const std::size_t count : {std::size_t{1}, std::size_t{64}, std::size_t{4096}}) {
    const std::size_t steps = std::max<std::size_t>(1, state_steps / count);
    Configuration configurations[] = {
        {"compiled in, analytic (reference)",
         [&](std::size_t c, std::size_t s, double& sum) { return time_steps(compiled_analytic, c, s, sum); }},
        {"plugin, analytic",
         [&](std::size_t c, std::size_t s, double& sum) { return time_steps(plugin_analytic, c, s, sum); }},
        {"compiled in, AD",
         [&](std::size_t c, std::size_t s, double& sum) { return time_steps(compiled_automatic, c, s, sum); }},
        {"plugin, AD",
         [&](std::size_t c, std::size_t s, double& sum) { return time_steps(plugin_automatic, c, s, sum); }},
    };
    double warm_up = 0.0;
    for (auto& configuration : configurations) configuration.run(count, steps / 10 + 1, warm_up);
    for (int r = 0; r < repetitions; ++r)
      for (auto& configuration : configurations)
        configuration.steps_per_second.push_back(static_cast<double>(steps * count) /
                                                 configuration.run(count, steps, configuration.checksum));
    const double reference = median(configurations[0].steps_per_second);
    for (const auto& configuration : configurations) {
      const double rate = median(configuration.steps_per_second);
      std::printf("%-8zu %-34s %16.4g %12.3f\n", count, configuration.name, rate, rate / reference);
    }
    const double plugin_over_compiled = median(configurations[1].steps_per_second) / reference;
    const double automatic_over_analytic_compiled = median(configurations[2].steps_per_second) / reference;
    const double automatic_over_analytic_plugin =
        median(configurations[3].steps_per_second) / median(configurations[1].steps_per_second);
    std::printf("%-8zu ratios: plugin/compiled-in %.3f, AD/analytic compiled-in %.3f, AD/analytic plugin %.3f\n", count,
                plugin_over_compiled, automatic_over_analytic_compiled, automatic_over_analytic_plugin);
    // Same model and arithmetic through the plugin: bit-for-bit the same final state. AD rounds differently from
    // the analytic formula, so its trajectories agree closely but not exactly.
    const bool identical = configurations[1].checksum == configurations[0].checksum &&
                           configurations[3].checksum == configurations[2].checksum;
    const bool close = std::abs(configurations[2].checksum - configurations[0].checksum) < 1e-9;
    std::printf("%-8zu final states: plugin = compiled in %s, AD ~ analytic %s\n", count, identical ? "yes" : "NO",
                close ? "yes" : "NO");
    if (!identical || !close) return 1;
  }
  return 0;
}
