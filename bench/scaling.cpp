// Cost per step against the dimension n (docs/scaling.md): the lattice chain plugin (plugins/lattice_chain) at
// n = 10 .. 10^6, each configuration's time per step as a ratio to one gradient evaluation (grad V, the
// hand-written analytic gradient behind the plugin boundary) in the same run.
//
// Configurations: one gradient (the unit), one Hessian-vector product, the energy H of one state (the plugin's own
// energy_TTV, and through grad T and hvp_V as for a plugin without it); Chin's basic step written out by hand
// (HandWrittenLatticeStep: the machine's limit for the step's memory traffic; its numbers are checked against the
// plugin's before it is timed); and the schemes Chin basic, MPE 4 (6 terms), triplet 2 (2 levels), Tao 4 (omega 20),
// Gauss 6 (3 stages), each plain and with the energy every step, Chin's also with one tangent vector (a Lyapunov
// vector; Tao and Gauss have no tangent map). Each is repeated `repeats` times (interleaved over
// the configurations, so that a busy spell of the machine spreads over all of them); each repetition runs as many
// steps as fit in about `budget` seconds of its first calibration run. Output: CSV on stdout,
//   n, configuration, seconds per step (median), lowest, highest, median / the gradient's median
//
// Usage: nonsep_bench_scaling [--smoke] [--n N ...] [--repeats R] [--budget SECONDS]
//        nonsep_bench_scaling --trajectory N STEPS   one trajectory of dimension N with the energy every step and
//                                                     one tangent vector (measure its memory with /usr/bin/time -v)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <memory>
#include <numbers>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/core/schemes/chin_basic_step.hpp"
#include "nonsep/core/schemes/gauss_legendre.hpp"
#include "nonsep/core/schemes/multi_product_expansion.hpp"
#include "nonsep/core/schemes/tao_extended_phase_space.hpp"
#include "nonsep/core/schemes/triplet_composition.hpp"
#include "nonsep/core/tangent/tangent_basic_step.hpp"
#include "nonsep/core/tangent/tangent_multi_product_expansion.hpp"
#include "nonsep/core/tangent/tangent_triplet_composition.hpp"
#include "nonsep/host/plugin_loader.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using nonsep::PhaseSpaceBatch;
using nonsep::host::PluginModel;

PluginModel lattice(std::size_t n) {
  return nonsep::host::load_plugin(std::string(NONSEP_BUILD_PLUGIN_DIR) + "/lattice_chain.so", "")
      .create({{"sites", n}});
}

// A wave of wavelength 10 sites, q_i = 0.3 sin(2 pi i / 10), p_i = 0.2 cos(2 pi i / 10), the same locally at every
// n (bond strains |r| <= 0.19, so that dt = 0.01 is stable and the Gauss iteration contracts).
PhaseSpaceBatch initial_state(std::size_t n) {
  PhaseSpaceBatch x(n, 1);
  for (std::size_t i = 0; i < n; ++i) {
    const double phase = 2.0 * std::numbers::pi * static_cast<double>(i % 10) / 10.0;
    x.q()[i] = 0.3 * std::sin(phase);
    x.p()[i] = 0.2 * std::cos(phase);
  }
  return x;
}

// The limit of the basic step at n: the nine flows of eq. (expalg) with the lattice's gradients (the plugin's default
// parameters a = 1, k = 0.5, b = 1) written out inside each flow, no plugin boundary, no batch bookkeeping: nine
// passes over the chain per step (five kicks, each computing grad V as it goes, four drifts with grad T), where the
// evaluation path makes seventeen (nine flows, eight gradients).
struct HandWrittenLatticeStep {
  static constexpr double a = 1.0, k = 0.5, b = 1.0;
  nonsep::ChinCoefficients c = nonsep::ChinCoefficients::from_t2(nonsep::ChinCoefficients::default_t2());
  std::vector<double> force;  // grad V of the current kick, so that the kick reads q as it was

  static double bond_force(double r) { return (k + b * r * r) * r; }
  void kick(std::span<const double> q, std::span<double> p, double h) {
    const std::size_t n = q.size();
    force.resize(n);
    force[0] = q[0] + bond_force(q[0] - q[n - 1]) - bond_force(q[1] - q[0]);
    for (std::size_t i = 1; i + 1 < n; ++i) force[i] = q[i] + bond_force(q[i] - q[i - 1]) - bond_force(q[i + 1] - q[i]);
    force[n - 1] = q[n - 1] + bond_force(q[n - 1] - q[n - 2]) - bond_force(q[0] - q[n - 1]);
    for (std::size_t i = 0; i < n; ++i) p[i] -= h * force[i];
  }
  static void drift(std::span<double> q, std::span<const double> p, double h) {
    for (std::size_t i = 0; i < q.size(); ++i) q[i] += h * (p[i] + a / 3.0 * p[i] * p[i] * p[i]);
  }
  void step(PhaseSpaceBatch& x, double eps) {
    const auto q = x.q(), p = x.p();
    kick(q, p, c.v2 * eps);
    drift(q, p, c.t2 * eps);
    kick(q, p, c.v1 * eps);
    drift(q, p, c.t1 * eps);
    kick(q, p, c.v0 * eps);
    drift(q, p, c.t1 * eps);
    kick(q, p, c.v1 * eps);
    drift(q, p, c.t2 * eps);
    kick(q, p, c.v2 * eps);
  }
};

// One configuration: `run(steps)` performs `steps` steps (or evaluations) on its own state.
struct Configuration {
  Configuration(std::string name_, std::function<void(std::uint64_t)> run_)
      : name(std::move(name_)), run(std::move(run_)) {}
  std::string name;
  std::function<void(std::uint64_t)> run;
  std::uint64_t steps = 1;
  std::vector<double> seconds_per_step;
};

std::vector<Configuration> configurations(const PluginModel& model) {
  const std::size_t n = model.dimension();
  const double dt = 0.01;
  auto x = std::make_shared<PhaseSpaceBatch>(initial_state(n));
  auto v = std::make_shared<std::vector<double>>(n, 1.0), out = std::make_shared<std::vector<double>>(n);
  auto energy = std::make_shared<nonsep::EnergyEvaluator>(nonsep::HamiltonianForm::TTV);
  std::vector<Configuration> list;
  list.push_back({"gradient", [=, &model](std::uint64_t s) {
                    for (std::uint64_t k = 0; k < s; ++k) model.grad_V(x->q(), *out, 1);
                  }});
  list.push_back({"hessian_vector_product", [=, &model](std::uint64_t s) {
                    for (std::uint64_t k = 0; k < s; ++k) model.hvp_V(x->q(), *v, *out, 1);
                  }});
  list.push_back({"energy", [=, &model](std::uint64_t s) {
                    for (std::uint64_t k = 0; k < s; ++k) (*out)[0] = energy->evaluate_one(model, *x);
                  }});
  // H as a plugin without energy_TTV gets it: grad T, hvp_V and their dot product.
  auto through_products = std::make_shared<PluginModel>(model.without_product_energy());
  list.push_back({"energy_by_products", [=](std::uint64_t s) {
                    for (std::uint64_t k = 0; k < s; ++k) (*out)[0] = energy->evaluate_one(*through_products, *x);
                  }});
  // Each stepping configuration owns its state, stepper and (for the tangent) vector.
  auto stepping = [&](const std::string& name, auto stepper) {
    auto state = std::make_shared<PhaseSpaceBatch>(initial_state(n));
    auto owned = std::make_shared<decltype(stepper)>(std::move(stepper));
    list.push_back({name, [=, &model](std::uint64_t s) {
                      for (std::uint64_t k = 0; k < s; ++k) owned->step(model, *state, dt);
                    }});
  };
  stepping("basic", nonsep::ChinBasicStep());
  {
    auto state = std::make_shared<PhaseSpaceBatch>(initial_state(n));
    auto stepper = std::make_shared<HandWrittenLatticeStep>();
    const double eps = std::cbrt(dt);
    list.push_back({"basic_hand_written", [=](std::uint64_t s) {
                      for (std::uint64_t k = 0; k < s; ++k) stepper->step(*state, eps);
                    }});
  }
  // Each scheme with the energy every step; Chin's schemes also with one tangent vector (a Lyapunov vector; Tao's
  // and Gauss's steps have no tangent map).
  auto with_energy = [&](const std::string& name, auto stepper) {
    auto state = std::make_shared<PhaseSpaceBatch>(initial_state(n));
    auto owned = std::make_shared<decltype(stepper)>(std::move(stepper));
    list.push_back({name + "_energy_every_step", [=, &model](std::uint64_t s) {
                      for (std::uint64_t k = 0; k < s; ++k) {
                        owned->step(model, *state, dt);
                        (*out)[0] = energy->evaluate_one(model, *state);
                      }
                    }});
  };
  auto with_tangent = [&](const std::string& name, auto stepper) {
    auto state = std::make_shared<PhaseSpaceBatch>(initial_state(n));
    auto tangent = std::make_shared<PhaseSpaceBatch>(n, 1);
    std::fill(tangent->q().begin(), tangent->q().end(), 1.0 / static_cast<double>(n));
    auto owned = std::make_shared<decltype(stepper)>(std::move(stepper));
    list.push_back({name + "_one_tangent_vector", [=, &model](std::uint64_t s) {
                      for (std::uint64_t k = 0; k < s; ++k) owned->step(model, *state, *tangent, dt);
                    }});
  };
  using nonsep::SeparableBasicStep;
  with_energy("basic", nonsep::ChinBasicStep());
  with_tangent("basic", nonsep::TangentBasicStep());
  stepping("mpe_4", nonsep::MultiProductExpansion<>(nonsep::ChinBasicStep(), 6));
  with_energy("mpe_4", nonsep::MultiProductExpansion<>(nonsep::ChinBasicStep(), 6));
  with_tangent("mpe_4", nonsep::TangentMultiProductExpansion(
                            nonsep::MultiProductExpansion<SeparableBasicStep>(SeparableBasicStep(), 6)));
  stepping("triplet_2", nonsep::TripletComposition<>(nonsep::ChinBasicStep(), 2));
  with_energy("triplet_2", nonsep::TripletComposition<>(nonsep::ChinBasicStep(), 2));
  with_tangent("triplet_2", nonsep::TangentTripletComposition(
                                nonsep::TripletComposition<SeparableBasicStep>(SeparableBasicStep(), 2)));
  stepping("tao_4", nonsep::TaoExtendedPhaseSpace(nonsep::HamiltonianForm::TTV, 4, 20.0));
  with_energy("tao_4", nonsep::TaoExtendedPhaseSpace(nonsep::HamiltonianForm::TTV, 4, 20.0));
  stepping("gauss_6", nonsep::GaussLegendre(nonsep::HamiltonianForm::TTV, 6));
  with_energy("gauss_6", nonsep::GaussLegendre(nonsep::HamiltonianForm::TTV, 6));
  return list;
}

// Whether the hand-written step follows the plugin's basic step: 3 steps from the initial state agree to 1e-12
// (the order of operations differs, so not bit for bit). Reports on stderr.
bool hand_written_agrees(const PluginModel& model) {
  const std::size_t n = model.dimension();
  auto by_hand = initial_state(n), by_plugin = by_hand;
  HandWrittenLatticeStep hand_written;
  nonsep::ChinBasicStep basic;
  for (int s = 0; s < 3; ++s) {
    hand_written.step(by_hand, std::cbrt(0.01));
    basic.step(model, by_plugin, 0.01);
  }
  double largest = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    largest =
        std::max({largest, std::abs(by_hand.q()[i] - by_plugin.q()[i]), std::abs(by_hand.p()[i] - by_plugin.p()[i])});
  if (largest <= 1e-12) return true;
  std::fprintf(stderr, "n = %zu: the hand-written step differs from the plugin's by %.3e after 3 steps\n", n, largest);
  return false;
}

double seconds(const std::function<void(std::uint64_t)>& run, std::uint64_t steps) {
  const auto start = Clock::now();
  run(steps);
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t m = values.size() / 2;
  return values.size() % 2 ? values[m] : 0.5 * (values[m - 1] + values[m]);
}

bool measure(std::size_t n, int repeats, double budget) {
  const PluginModel model = lattice(n);
  if (!hand_written_agrees(model)) return false;
  auto list = configurations(model);
  // A configuration that fails (Gauss' fixed-point iteration stalling at round-off, say) is reported on stderr and
  // left out of the table.
  std::vector<bool> failed(list.size(), false);
  auto attempt = [&](std::size_t i, const std::function<void()>& work) {
    if (failed[i]) return;
    try {
      work();
    } catch (const std::exception& error) {
      failed[i] = true;
      std::fprintf(stderr, "n = %zu, %s: %s\n", n, list[i].name.c_str(), error.what());
    }
  };
  for (std::size_t i = 0; i < list.size(); ++i)
    attempt(i, [&] {
      const double once = seconds(list[i].run, 1);
      list[i].steps = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(budget / std::max(once, 1e-9)));
    });
  for (int r = 0; r < repeats; ++r)
    for (std::size_t i = 0; i < list.size(); ++i)
      attempt(i, [&] {
        list[i].seconds_per_step.push_back(seconds(list[i].run, list[i].steps) / static_cast<double>(list[i].steps));
      });
  const double unit = median(list.front().seconds_per_step);
  for (std::size_t i = 0; i < list.size(); ++i) {
    const Configuration& c = list[i];
    if (failed[i]) continue;
    const auto [low, high] = std::minmax_element(c.seconds_per_step.begin(), c.seconds_per_step.end());
    const double m = median(c.seconds_per_step);
    std::printf("%zu,%s,%.6e,%.6e,%.6e,%.3f\n", n, c.name.c_str(), m, *low, *high, m / unit);
    std::fflush(stdout);
  }
  return true;
}

void trajectory(std::size_t n, std::uint64_t steps) {
  const PluginModel model = lattice(n);
  auto x = initial_state(n);
  PhaseSpaceBatch tangent(n, 1);
  std::fill(tangent.q().begin(), tangent.q().end(), 1.0 / static_cast<double>(n));
  nonsep::TangentBasicStep stepper;
  nonsep::EnergyEvaluator energy(nonsep::HamiltonianForm::TTV);
  const double h0 = energy.evaluate_one(model, x);
  double worst = 0.0;
  for (std::uint64_t s = 0; s < steps; ++s) {
    stepper.step(model, x, tangent, 0.01);
    worst = std::max(worst, std::abs(energy.evaluate_one(model, x) - h0) / std::abs(h0));
  }
  std::printf(
      "n = %zu, %llu steps with the energy every step and one tangent vector: largest relative energy "
      "error %.3e\n",
      n, static_cast<unsigned long long>(steps), worst);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::size_t> sizes = {10, 100, 1000, 10000, 100000, 1000000};
  int repeats = 5;
  double budget = 0.05;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--smoke") {
      sizes = {10, 100};
      repeats = 1;
      budget = 0.002;
    } else if (arg == "--n" && i + 1 < argc) {
      sizes.clear();
      while (i + 1 < argc && argv[i + 1][0] != '-') sizes.push_back(std::strtoull(argv[++i], nullptr, 10));
    } else if (arg == "--repeats" && i + 1 < argc) {
      repeats = std::atoi(argv[++i]);
    } else if (arg == "--budget" && i + 1 < argc) {
      budget = std::atof(argv[++i]);
    } else if (arg == "--trajectory" && i + 2 < argc) {
      const std::size_t n = std::strtoull(argv[i + 1], nullptr, 10);
      trajectory(n, std::strtoull(argv[i + 2], nullptr, 10));
      return 0;
    } else {
      std::fprintf(stderr,
                   "usage: nonsep_bench_scaling [--smoke] [--n N ...] [--repeats R] [--budget SECONDS] | "
                   "--trajectory N STEPS\n");
      return 2;
    }
  }
  if (repeats < 1 || budget <= 0.0 || sizes.empty()) {
    std::fprintf(stderr, "nonsep_bench_scaling: --repeats must be >= 1, --budget > 0, --n at least one size\n");
    return 2;
  }
  std::printf("n,configuration,seconds_per_step,lowest,highest,ratio_to_gradient\n");
  for (const std::size_t n : sizes)
    if (!measure(n, repeats, budget)) return 1;
  return 0;
}
