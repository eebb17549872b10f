// The key tables of a job's /analysis section and its /analysis/poincare and /analysis/lyapunov objects
// (job_keys.hpp). Descriptions are the schema's; the limits are the analyses' own constants.
#include <limits>

#include "job_keys.hpp"
#include "nonsep/core/lyapunov_exponents.hpp"

namespace nonsep::host::job_reader {

const KeyTable& analysis_keys() {
  static const KeyTable table{{
      {.name = "closest_return_after",
       .type = ValueType::finite,
       .description = "From |t| >= this time on, the smallest Euclidean phase-space distance |(q, p) - (q0, p0)| "
                      "of each trajectory to its initial state is tracked at every step (trajectories.csv: "
                      "closest_return_distance, _t, _step)."},
      {.name = "max_relative_energy_error",
       .type = ValueType::positive,
       .description = "A bound on the relative energy error |H(t) - H0| / |H0|: a trajectory that exceeds it is "
                      "retired with status \"inaccurate\". Absent: no bound."},
      {.name = "poincare",
       .type = ValueType::object,
       .description = "A surface of section normal . (q, p) = value: every crossing of every trajectory goes to "
                      "poincare.csv (trajectory, crossing, step, t, q, p, H), located on the numerical trajectory by "
                      "a fractional step of the run's integrator (|normal . (q, p) - value| at round-off). Exactly "
                      "one of component and normal.",
       .keys = poincare_keys},
      {.name = "lyapunov",
       .type = ValueType::object,
       .description = "Finite-time Lyapunov exponents (Benettin et al.) from the exact tangent map of the run's "
                      "integrator: trajectories.csv columns lyapunov0 .. lyapunov<k-1>. The plugin must have "
                      "Hessians. The first tangent vector is (1, 1/2, ..., 1/(2n)) over (dq, dp), normalised.",
       .keys = lyapunov_keys},
      {.name = "megno",
       .type = ValueType::boolean,
       .default_value = false,
       .description = "MEGNO of the first tangent vector (Cincotta and Simo): trajectories.csv columns megno (Y) and "
                      "mean_megno (<Y>: -> 2 on quasi-periodic orbits, ~ lambda t / 2 on chaotic ones). The plugin "
                      "must have Hessians."},
      {.name = "sali",
       .type = ValueType::boolean,
       .default_value = false,
       .description = "SALI of the first two tangent vectors (Skokos 2001), min(|u1 + u2|, |u1 - u2|) of their unit "
                      "vectors: trajectories.csv column sali (-> 0 exponentially on chaotic orbits, stays away from 0 "
                      "on regular ones). Shares the vectors of lyapunov (at least 2). The plugin must have Hessians."},
      {.name = "gali",
       .type = ValueType::integer,
       .minimum = 2,
       .maximum = static_cast<std::int64_t>(LyapunovRecord::max_exponents),
       .description = "k (at most 2n): GALI_2 .. GALI_k (Skokos, Bountis and Antonopoulos 2007), the volume spanned "
                      "by the unit vectors of the first j tangent vectors: trajectories.csv columns gali2 .. gali<k> "
                      "(exponential decay on chaotic orbits; constant for j <= N, ~ t^(-2(j-N)) on an N-torus). Shares "
                      "the vectors of lyapunov. The plugin must have Hessians."},
  }};
  return table;
}

const KeyTable& poincare_keys() {
  static const KeyTable table{
      {
          {.name = "component",
           .type = ValueType::string,
           .description = "The plane component = value, e.g. \"q0\" or \"p1\" (0-based, below the dimension).",
           .pattern = "^[qp](0|[1-9][0-9]*)$"},
          {.name = "normal",
           .type = ValueType::defined,
           .description = "2n numbers, n for q then n for p, not all zero.",
           .definition = "vector"},
          {.name = "value",
           .type = ValueType::finite,
           .default_value = 0,
           .description = "The offset c of the plane normal . (q, p) = c."},
          {.name = "offset", .type = ValueType::finite, .default_value = 0, .description = "Another name for value."},
          {.name = "direction",
           .type = ValueType::choice,
           .default_value = "+",
           .description = "\"+\": crossings where normal . (q, p) - value goes from < 0 to >= 0; \"-\": from > 0 "
                          "to <= 0; \"both\".",
           .choices = {"+", "-", "both"}},
          {.name = "max_crossings",
           .type = ValueType::integer,
           .minimum = 1,
           .maximum = std::numeric_limits<std::int64_t>::max(),
           .description = "A trajectory stops at the step of its N-th crossing, with status \"completed\" and a "
                          "message saying so. Absent: no limit."},
      },
      {{"oneOf", {{{"required", {"component"}}}, {{"required", {"normal"}}}}},
       {"not", {{"required", {"value", "offset"}}}}}};
  return table;
}

const KeyTable& lyapunov_keys() {
  static const KeyTable table{{
      {.name = "vectors",
       .type = ValueType::integer,
       .minimum = 1,
       .maximum = static_cast<std::int64_t>(LyapunovRecord::max_exponents),
       .default_value = 1,
       .description = "k, the number of largest exponents (at most 2n)."},
      {.name = "renormalize_every",
       .type = ValueType::integer,
       .minimum = 1,
       .maximum = steps_limit,
       .default_value = 1,
       .description = "Steps between re-orthonormalisations (modified Gram-Schmidt) of the tangent vectors."},
      {.name = "every",
       .type = ValueType::integer,
       .minimum = 0,
       .maximum = steps_limit,
       .default_value = 0,
       .description = "Write the running estimates to lyapunov.csv every n-th step (with megno and mean_megno when "
                      "megno is true, sali and gali2 .. gali<k> when asked); 0: no time series."},
  }};
  return table;
}

}  // namespace nonsep::host::job_reader
