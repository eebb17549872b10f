// /initial/energy and /initial/solve_for: a grid of initial states put on one energy shell H(q, p) = E by solving for
// one momentum component, the helper behind Poincare phase portraits (examples/dynamics). The root is bracketed
// from p_i = 0 outwards (doubling) and refined by Boost.Math's TOMS 748 to the last bits; the state keeps the
// evaluated p_i with the smallest |H - E|.
#include <boost/math/tools/toms748_solve.hpp>
#include <cmath>

#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/core/base/error.hpp"
#include "nonsep/host/number_format.hpp"
#include "sections.hpp"

namespace nonsep::host {

namespace job_reader {

void read_energy_shell(Checker& check, const KeyReader& initial, InitialStates& states) {
  // Both or neither (the table's pair).
  if (!initial.given("energy") || !initial.pairs_hold()) return;
  EnergyShell shell;
  const auto energy = initial.number("energy");
  const auto solve = initial.string("solve_for");
  if (!solve) return;  // refused by the table
  std::string text = *solve;
  shell.solve_for = text;
  shell.negative = text[0] == '-';
  if (shell.negative) text.erase(0, 1);
  bool valid = text.size() >= 2 && text[0] == 'p' && text.size() < 8;
  for (std::size_t i = 1; valid && i < text.size(); ++i) valid = text[i] >= '0' && text[i] <= '9';
  if (valid) shell.component = static_cast<std::size_t>(std::stoul(text.substr(1)));
  if (!valid || (states.dimension > 0 && shell.component >= states.dimension)) {
    check.issue("/initial/solve_for", describe(initial.object()["solve_for"]),
                "\"p<i>\" (the root p_i >= 0) or \"-p<i>\" (the root p_i <= 0), i from 0 to " +
                    std::to_string(states.dimension > 0 ? states.dimension - 1 : 0));
    return;
  }
  if (!energy) return;
  shell.energy = *energy;
  states.shell = shell;
}

}  // namespace job_reader

std::size_t solve_on_energy_shell(const PluginModel& model, HamiltonianForm form, const EnergyShell& shell,
                                  std::size_t n, std::vector<double>& states_q, std::vector<double>& states_p) {
  const std::size_t c = shell.component, count = states_q.size() / n;
  EnergyEvaluator evaluator(form);
  std::vector<double> q, p, kept_q, kept_p;
  // H - E at p_c = x for the state being solved.
  auto excess = [&](double x) {
    p[c] = shell.negative ? -x : x;
    double h = 0.0;
    try {
      evaluator.evaluate(model, PhaseSpaceBatch::single(q, p), std::span<double>(&h, 1));
    } catch (const ModelError&) {
      return std::nan("");  // not bracketed: the state is left out
    }
    return h - shell.energy;
  };
  std::size_t left_out = 0;
  for (std::size_t b = 0; b < count; ++b) {
    q.assign(states_q.begin() + static_cast<std::ptrdiff_t>(b * n),
             states_q.begin() + static_cast<std::ptrdiff_t>((b + 1) * n));
    p.assign(states_p.begin() + static_cast<std::ptrdiff_t>(b * n),
             states_p.begin() + static_cast<std::ptrdiff_t>((b + 1) * n));
    double lower = 0.0, g_lower = excess(0.0), upper = 1.0, g_upper = 0.0;
    bool bracketed = false;
    if (std::isfinite(g_lower) && g_lower <= 0.0) {
      for (; upper <= 0x1p40; upper *= 2.0) {
        g_upper = excess(upper);
        if (!std::isfinite(g_upper)) break;
        if (g_upper >= 0.0) {
          bracketed = true;
          break;
        }
        lower = upper;
        g_lower = g_upper;
      }
    }
    if (!bracketed) {
      ++left_out;
      continue;
    }
    double root = g_lower == 0.0 ? lower : upper;
    if (g_lower != 0.0 && g_upper != 0.0) {
      std::uintmax_t iterations = 200;
      const auto range = boost::math::tools::toms748_solve(excess, lower, upper, g_lower, g_upper,
                                                           boost::math::tools::eps_tolerance<double>(), iterations);
      root = std::abs(excess(range.first)) <= std::abs(excess(range.second)) ? range.first : range.second;
    }
    p[c] = shell.negative ? -root : root;
    kept_q.insert(kept_q.end(), q.begin(), q.end());
    kept_p.insert(kept_p.end(), p.begin(), p.end());
  }
  states_q = std::move(kept_q);
  states_p = std::move(kept_p);
  return left_out;
}

}  // namespace nonsep::host
