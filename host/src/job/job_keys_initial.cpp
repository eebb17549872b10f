// The key tables of a job's /initial (a state, a grid of states with its energy shell, a file of states) and the
// lists of numbers of every section (job_keys.hpp). Descriptions are the schema's; the limits are the reader's own
// constants (job.hpp, time_grid.hpp).
#include <string>

#include "job_keys.hpp"
#include "nonsep/host/job.hpp"

namespace nonsep::host::job_reader {

const KeyTable& state_keys() {
  static const KeyTable table{{
      {.name = "q",
       .type = ValueType::defined,
       .required = true,
       .description = "Positions, one per degree of freedom.",
       .allowed = "the positions, an array of finite numbers",
       .definition = "vector"},
      {.name = "p",
       .type = ValueType::defined,
       .required = true,
       .description = "Momenta, as many as q.",
       .allowed = "the momenta, an array of finite numbers",
       .definition = "vector"},
  }};
  return table;
}

const KeyTable& initial_grid_keys() {
  static const KeyTable table{
      {
          {.name = "grid",
           .type = ValueType::object,
           .required = true,
           .description = "One axis per component of q and of p; the states are every combination, in row-major order "
                          "over q0, q1, ..., p0, p1, ... (the last axis varies fastest). At most " +
                          std::to_string(max_initial_states) + " states, and at most " +
                          std::to_string(max_initial_values) + " numbers in q (states times dimension).",
           .keys = grid_keys},
          {.name = "energy",
           .type = ValueType::finite,
           .description = "Put every state of the grid on the energy shell H = energy by solving for the momentum "
                          "component solve_for names (the grid's value of it is ignored); states that cannot reach the "
                          "shell are left out (summary.json energy_shell.left_out).",
           .allowed = "a finite number: the energy H of every state"},
          {.name = "solve_for",
           .type = ValueType::string,
           .description = "\"p<i>\": the root p_i >= 0 nearest to 0; \"-p<i>\": the root p_i <= 0.",
           .allowed = "\"p<i>\" (the root p_i >= 0) or \"-p<i>\" (the root p_i <= 0), i from 0 below the dimension",
           .pattern = "^-?p(0|[1-9][0-9]*)$"},
      },
      {{KeyPair::Kind::together, "energy", "solve_for",
        "\"energy\" and \"solve_for\" together: the component p_i solved for so that H = energy"}}};
  return table;
}

const KeyTable& initial_file_keys() {
  static const KeyTable table{{
      {.name = "file",
       .type = ValueType::path,
       .required = true,
       .description = "The states in a file, relative to the job file's folder, one state per row, q0..q(n-1) then "
                      "p0..p(n-1): a NumPy .npy file of a little-endian float64 array of shape (states, 2n) or (2n,) "
                      "(numpy.save), or a .csv file with the header q0,...,q(n-1),p0,...,p(n-1). At most " +
                      std::to_string(max_initial_states) + " states and " + std::to_string(max_initial_values) +
                      " numbers in q, every number finite.",
       .allowed = "the path of a .npy or .csv file of initial states, relative to the job file's folder"},
  }};
  return table;
}

const KeyTable& grid_keys() {
  static const KeyTable table{{
      {.name = "q",
       .type = ValueType::defined,
       .required = true,
       .description = "The axes of q0, q1, ...",
       .allowed = "an array of axes, one per component",
       .definition = "axes"},
      {.name = "p",
       .type = ValueType::defined,
       .required = true,
       .description = "The axes of p0, p1, ...",
       .allowed = "an array of axes, one per component",
       .definition = "axes"},
  }};
  return table;
}

const KeyTable& range_axis_keys() {
  static const KeyTable table{{
      {.name = "from",
       .type = ValueType::finite,
       .required = true,
       .description = "The first value.",
       .allowed = "the first value, a finite number"},
      {.name = "to",
       .type = ValueType::finite,
       .required = true,
       .description = "The last value.",
       .allowed = "the last value, a finite number"},
      {.name = "count",
       .type = ValueType::integer,
       .required = true,
       .minimum = 1,
       .maximum = states_limit,
       .description = "The number of values.",
       .allowed = "the number of values, an integer from 1 to " + std::to_string(states_limit)},
  }};
  return table;
}

const KeyTable& values_axis_keys() {
  static const KeyTable table{{
      {.name = "values",
       .type = ValueType::defined,
       .required = true,
       .description = "The values listed.",
       .definition = "values"},
  }};
  return table;
}

const std::vector<NumberList>& number_lists() {
  static const std::vector<NumberList> lists{
      {.definition = "vector",
       .item = {.type = ValueType::finite, .allowed = "a finite number"},
       .max_items = max_initial_values,
       .allowed = "a non-empty array of finite numbers, one per degree of freedom"},
      {.definition = "normal",
       .item = {.type = ValueType::finite, .allowed = "a finite number"},
       .max_items = 2 * max_initial_values,
       .allowed = "a non-empty array of finite numbers, 2n: n for q, then n for p"},
      {.definition = "values",
       .item = {.type = ValueType::finite, .allowed = "a finite number"},
       .max_items = max_initial_states,
       .allowed = "a non-empty array of finite numbers"},
      {.definition = "indices",
       .item = {.type = ValueType::integer, .minimum = 0, .maximum = int64_limit, .allowed = "an integer >= 0"},
       .max_items = max_initial_values,
       .distinct = true,
       .allowed = "a non-empty array of distinct integers >= 0"},
      {.definition = "step_counts",
       .item = {.type = ValueType::integer,
                .minimum = 1,
                .maximum = steps_limit,
                .allowed = "a step count, an integer from 1 to " + std::to_string(steps_limit)},
       .max_items = max_initial_states,
       .distinct = true,
       .description = "Step counts over t_end: dt = t_end / steps exactly.",
       .allowed = "a non-empty array of distinct step counts, integers from 1 to " + std::to_string(steps_limit)},
      {.definition = "step_sizes",
       .item = {.type = ValueType::nonzero, .allowed = "a step size, a finite non-zero number"},
       .max_items = max_initial_states,
       .description = "Step sizes of the sign of t_end; each becomes steps = ceil((t_end/dt)(1 - 1e-9)) as in a run.",
       .allowed = "a non-empty array of step sizes, finite non-zero numbers of the sign of t_end"},
  };
  return lists;
}

const NumberList* number_list(std::string_view definition) {
  for (const auto& list : number_lists())
    if (list.definition == definition) return &list;
  return nullptr;
}

}  // namespace nonsep::host::job_reader
