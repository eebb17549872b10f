#pragma once
// Internal to the job reader (host/src/job/): the keys of every object of a job file, with their types, integer
// ranges, defaults and whether they are required. The section readers read their objects by these tables
// (KeyReader, key_reader.hpp: known keys, required keys, each value's type, range and choices, with the rule's
// `allowed` text as the message), and `nonsep schema` (job_schema.cpp) writes schemas/job.schema.json from the same
// tables and the scheme catalogue, so the schema cannot drift from the reader; tests/host/test_host_job_schema.cpp
// holds the readers to the types written here. Two keys of one object that relate are a pair of the table (exactly
// one of them, not both, both or neither); what relates a value to anything else (the state's dimension, t_end, the
// scheme's own verdict on an option) stays with the readers.
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "nonsep/core/schemes/chin_basic_step.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/time_grid.hpp"

namespace nonsep::host::job_reader {

enum class ValueType {
  object,       // an object whose keys are `keys` (or, without `keys`, any object: /time, checked per kind of job)
  text,         // any string (/description)
  string,       // a non-empty string
  path,         // a non-empty string without NUL (U+0000)
  finite,       // a finite number
  nonzero,      // a finite non-zero number
  positive,     // a finite number > 0
  nonnegative,  // a finite number >= 0
  integer,      // an integral number (10.0 counts) within [minimum, maximum]
  form,         // one of hamiltonian_forms()
  boolean,      // true or false
  choice,       // one of the strings `choices`
  order,    // a scheme's order: an exact fraction as a string ("4/3") or an integer (the scheme refuses one it lacks)
  defined,  // a shape of its own, $defs/<definition> of the schema (states, axes, integrators); the lists of
            // numbers among them (number_list) are checked by the table too
};

// The integer ranges the tables share: step counts up to the time grid's limit, ensembles up to the reader's.
inline constexpr std::int64_t steps_limit = static_cast<std::int64_t>(max_steps);
inline constexpr std::int64_t int64_limit = std::numeric_limits<std::int64_t>::max();
inline constexpr std::int64_t states_limit = static_cast<std::int64_t>(max_initial_states);

struct KeyTable;

struct KeyRule {
  std::string name = {};
  ValueType type = ValueType::finite;
  bool required = false;
  std::int64_t minimum = 0, maximum = 0;  // ValueType::integer
  // ValueType::finite: the closed range [at_least, at_most] (unbounded by default).
  double at_least = -std::numeric_limits<double>::infinity(), at_most = std::numeric_limits<double>::infinity();
  nlohmann::ordered_json default_value = nullptr;  // as a job file would write it; null: no default
  std::string description = {};                    // for the schema
  // What a message for a refused value says is allowed (key_reader.hpp); empty: one built from the type and range.
  std::string allowed = {};
  const KeyTable& (*keys)() = nullptr;    // ValueType::object
  std::string definition = {};            // ValueType::defined
  std::vector<std::string> choices = {};  // ValueType::choice
  std::string pattern = {};               // ValueType::string: a regular expression the string matches (in the schema)
  // A document key refused in a study: what the issue says was found and what is allowed instead.
  bool run_only = false;
  std::string in_study_found = {}, in_study_allowed = {};
};

// Two keys of one object that relate: the reader checks the pair (KeyReader) and the schema writes it (oneOf,
// dependentSchemas, dependentRequired), from this one line.
struct KeyPair {
  enum class Kind {
    exactly_one,  // one of the two, not both
    at_most_one,  // not both
    together,     // both or neither
  };
  Kind kind;
  std::string first, second;
  std::string allowed;  // what a message says is allowed
};

// The keys of one kind of object, in the order messages list them ("only the keys ..."), and how they pair.
struct KeyTable {
  std::vector<KeyRule> rules;
  std::vector<KeyPair> pairs = {};
  std::vector<std::string> names() const;
  std::vector<std::string> required() const;
  // The rule named `name`; a name without a rule is a programming error (std::logic_error).
  const KeyRule& operator[](std::string_view name) const;
};

// A list of numbers of a job file (the ValueType::defined rules of these definitions: "vector", "normal", "values",
// "indices", "step_counts", "step_sizes"): the reader checks its size, each item and distinctness, and the schema
// writes it under $defs, from here.
struct NumberList {
  std::string definition;
  KeyRule item;                  // one item: its type (finite, nonzero or integer), range and message
  std::size_t max_items = 0;     // more is refused before the items are read
  bool distinct = false;         // each value once
  std::string description = {};  // for the schema
  std::string allowed = {};      // the list as a whole, for messages
};
// The list described for `definition`, or nullptr when that definition is not a list of numbers.
const NumberList* number_list(std::string_view definition);
const std::vector<NumberList>& number_lists();

// The document and its sections.
const KeyTable& document_keys();
const KeyTable& model_keys();
const KeyTable& run_time_keys();    // a run's /time: "dt" and exactly one of "t_end", "steps"
const KeyTable& study_time_keys();  // a study's /time
const KeyTable& output_keys();
const KeyTable& analysis_keys();
const KeyTable& poincare_keys();     // /analysis/poincare
const KeyTable& frequencies_keys();  // /analysis/frequencies
const KeyTable& lyapunov_keys();     // /analysis/lyapunov
const KeyTable& checkpoint_keys();
const KeyTable& study_keys();  // at most one of "steps", "dt"
// /integrator {"scheme": "auto", ...}: the keys besides "scheme" (study/scheme_choice.hpp).
const KeyTable& auto_integrator_keys();
// The keys a study's integrator has besides the scheme's options (at most one of "steps", "dt").
const KeyTable& study_integrator_keys();
// /initial and the states of /study/reference.
const KeyTable& state_keys();
const KeyTable& initial_grid_keys();  // {"grid": ...}
const KeyTable& initial_file_keys();  // {"file": ...}
const KeyTable& grid_keys();          // {"q": axes, "p": axes}
const KeyTable& range_axis_keys();    // {"from", "to", "count"}
const KeyTable& values_axis_keys();   // {"values"}

// The names of /hamiltonian, the default first.
struct FormName {
  const char* name;
  HamiltonianForm form;
};
const std::vector<FormName>& hamiltonian_forms();

}  // namespace nonsep::host::job_reader
