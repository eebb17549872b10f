// The key tables of a job's /analysis section and its /analysis/poincare, /analysis/frequencies and
// /analysis/lyapunov objects
// (job_keys.hpp). Descriptions are the schema's; the limits are the analyses' own constants.
#include <limits>

#include "indicators.hpp"
#include "job_keys.hpp"
#include "nonsep/core/analysis/lyapunov_exponents.hpp"
#include "nonsep/host/number_format.hpp"

namespace nonsep::host::job_reader {

const KeyTable& analysis_keys() {
  // The indicators' keys (indicators.cpp: frequencies, then the chaos indicators) come before error_estimate.
  static const KeyTable table = [] {
    KeyTable t{{
        {.name = "closest_return_after",
         .type = ValueType::finite,
         .description = "From |t| >= this time on, the smallest Euclidean phase-space distance |(q, p) - (q0, p0)| "
                        "of each trajectory to its initial state is tracked at every step (trajectories.csv: "
                        "closest_return_distance, _t, _step).",
         .allowed = "a finite time: from then on the smallest phase-space distance to the initial state is "
                    "tracked"},
        {.name = "max_relative_energy_error",
         .type = ValueType::positive,
         .description = "A bound on the relative energy error |H(t) - H0| / |H0|: a trajectory that exceeds it is "
                        "retired with status \"inaccurate\". Absent: no bound.",
         .allowed = "a finite number > 0: a trajectory whose |H - H0| / |H0| exceeds it stops with status "
                    "\"inaccurate\""},
        {.name = "poincare",
         .type = ValueType::object,
         .description = "A surface of section normal . (q, p) = value: every crossing of every trajectory goes to "
                        "poincare.csv (trajectory, crossing, step, t, q, p, H), located on the numerical trajectory by "
                        "a fractional step of the run's integrator (|normal . (q, p) - value| at round-off). Exactly "
                        "one of component and normal.",
         .keys = poincare_keys},
    }};
    for (const IndicatorEntry& entry : indicator_entries()) t.rules.push_back(entry.rule);
    t.rules.push_back(
        {.name = "error_estimate",
         .type = ValueType::boolean,
         .default_value = false,
         .description = "Integrates every trajectory a second time with half the step and estimates the run's global "
                        "error by Richardson extrapolation with the scheme's order, at the samples (or 100 evenly "
                        "spaced steps without samples) and at the end: error_estimate.csv, trajectories.csv columns "
                        "estimated_phase_error, estimated_relative_energy_error, error_estimate_t, "
                        "error_estimate_horizon, error_estimate. Where the two runs separate (their difference above "
                        "0.1 of |(q, p)|: a chaotic orbit) the estimate ends: error_estimate_horizon is that time. "
                        "Costs twice the run.",
         .allowed = "true or false: estimate each trajectory's global error by a second run with half the step"});
    return t;
  }();
  return table;
}

const KeyTable& auto_integrator_keys() {
  static const KeyTable table{{
      {.name = "tolerance",
       .type = ValueType::finite,
       .required = true,
       .at_least = auto_tolerance_min,
       .at_most = auto_tolerance_max,
       .description = "The accuracy asked for: the global error at the end of the run (phase), or the largest "
                      "relative energy error |dH/H0| over the run (energy), between 1e-14 and 0.1. Pilot runs on "
                      "the job's own model and states choose the scheme and the step that meet it at the least "
                      "predicted cost; time.dt is then the output grid, which the chosen step divides.",
       .allowed = "a number from " + format_number(auto_tolerance_min) + " to " + format_number(auto_tolerance_max) +
                  ": the global error at t_end (phase) or the largest |dH/H0| over the run (energy)"},
      {.name = "measure",
       .type = ValueType::choice,
       .default_value = "phase",
       .description = "\"phase\": the phase-space error |(q, p) - (q, p)_exact| at t_end; \"energy\": the largest "
                      "|dH/H0| over the run (needs the plugin's Hessians).",
       .allowed = "\"phase\" (the phase-space error at t_end, the default) or \"energy\" (the largest |dH/H0|)",
       .choices = {"phase", "energy"}},
  }};
  return table;
}

const KeyTable& poincare_keys() {
  static const KeyTable table{
      {
          {.name = "component",
           .type = ValueType::string,
           .description = "The plane component = value, e.g. \"q0\" or \"p1\" (0-based, below the dimension).",
           .allowed = "\"q<i>\" or \"p<i>\" (i from 0, below the dimension), a component of the state",
           .pattern = "^[qp](0|[1-9][0-9]*)$"},
          {.name = "normal",
           .type = ValueType::defined,
           .description = "2n numbers, n for q then n for p, not all zero.",
           .definition = "normal"},
          {.name = "value",
           .type = ValueType::finite,
           .default_value = 0,
           .description = "The offset c of the plane normal . (q, p) = c.",
           .allowed = "a finite number: the plane is normal . (q, p) = value (default 0)"},
          {.name = "offset",
           .type = ValueType::finite,
           .default_value = 0,
           .description = "Another name for value.",
           .allowed = "a finite number: the plane is normal . (q, p) = value (default 0)"},
          {.name = "direction",
           .type = ValueType::choice,
           .default_value = "+",
           .description = "\"+\": crossings where normal . (q, p) - value goes from < 0 to >= 0; \"-\": from > 0 "
                          "to <= 0; \"both\".",
           .allowed = "\"+\" (normal . (q, p) - value goes from < 0 to >= 0; the default), \"-\" or \"both\"",
           .choices = {"+", "-", "both"}},
          {.name = "max_crossings",
           .type = ValueType::integer,
           .minimum = 1,
           .maximum = std::numeric_limits<std::int64_t>::max(),
           .description = "A trajectory stops at the step of its N-th crossing, with status \"completed\" and a "
                          "message saying so. Absent: no limit.",
           .allowed = "an integer >= 1: a trajectory stops (status \"completed\", with a message) at the step of its "
                      "N-th crossing"},
      },
      {{KeyPair::Kind::exactly_one, "component", "normal",
        "exactly one of \"component\" (\"q<i>\" or \"p<i>\", i from 0 below the dimension) and \"normal\" (2n "
        "numbers, n for q then n for p)"},
       {KeyPair::Kind::at_most_one, "value", "offset", "one of them: the plane is normal . (q, p) = value"}}};
  return table;
}

const KeyTable& frequencies_keys() {
  static const KeyTable table{{
      {.name = "every",
       .type = ValueType::integer,
       .minimum = 1,
       .maximum = steps_limit,
       .default_value = 1,
       .description = "Steps between samples: the signals are sampled at steps every, 2 every, ..., N every (N = "
                      "steps / every, at least 32).",
       .allowed = "an integer >= 1: steps between samples (default 1)"},
      {.name = "signals",
       .type = ValueType::defined,
       .description = "The degrees of freedom k whose signals q_k + i p_k are analysed, in column order (0-based, "
                      "below the dimension, each once). Absent: every degree of freedom.",
       .allowed = "a non-empty list of distinct degrees of freedom k (numbered from 0): the signals q_k + i p_k",
       .definition = "indices"},
      {.name = "spectra",
       .type = ValueType::integer,
       .minimum = 0,
       .maximum = 1000,
       .default_value = 0,
       .description = "Write the strongest this many terms (frequency, complex amplitude) of each signal over the "
                      "whole run to frequency_spectra.csv, at most samples / 4; 0: no such file.",
       .allowed = "an integer from 0 to 1000: terms per signal in frequency_spectra.csv (0: no file)"},
  }};
  return table;
}

const KeyTable& lyapunov_keys() {
  static const KeyTable table{{
      {.name = "vectors",
       .type = ValueType::integer,
       .minimum = 1,
       .maximum = static_cast<std::int64_t>(LyapunovRecord::max_exponents),
       .default_value = 1,
       .description = "k, the number of largest exponents (at most 2n).",
       .allowed = "an integer from 1 to 2n (at most 32): the number of largest exponents (default 1)"},
      {.name = "renormalize_every",
       .type = ValueType::integer,
       .minimum = 1,
       .maximum = steps_limit,
       .default_value = 1,
       .description = "Steps between re-orthonormalisations (modified Gram-Schmidt) of the tangent vectors.",
       .allowed = "an integer >= 1: steps between re-orthonormalisations of the tangent vectors (default 1)"},
      {.name = "every",
       .type = ValueType::integer,
       .minimum = 0,
       .maximum = steps_limit,
       .default_value = 0,
       .description = "Write the running estimates to lyapunov.csv every n-th step (with megno and mean_megno when "
                      "megno is true, sali and gali2 .. gali<k> when asked); 0: no time series.",
       .allowed = "an integer >= 0: write lyapunov.csv every n-th step (0: no time series; the default)"},
  }};
  return table;
}

}  // namespace nonsep::host::job_reader
