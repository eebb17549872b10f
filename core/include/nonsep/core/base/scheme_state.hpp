#pragma once
// A scheme's private state, for a runner that checkpoints and reports (the host's driver, checkpoint.json and
// summary.json): what a stepper keeps per state beyond (q, p) between steps, and what it tracks over a run, as
// named numbers that the runner stores and hands back without knowing what they mean. Tao's extended phase space
// (tao_extended_phase_space.hpp) keeps the copy (x, y) of each state and the largest copy distance so far; the
// other schemes keep nothing (an empty SchemeState).
#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

namespace nonsep {

struct SchemeState {
  struct Column {
    std::string name;            // a key of the runner's files ("copies_q")
    std::size_t per_state = 0;   // numbers per state
    std::vector<double> values;  // state-major: the per_state numbers of the first state, of the second, ...
  };
  // A number about the run that only grows ("max_copy_distance"): the runner's parts (blocks of states) combine
  // by taking the largest.
  struct Largest {
    std::string name;
    double value = 0.0;
  };
  std::vector<Column> columns;
  std::vector<Largest> largest;

  // Appends `part` (the same scheme's state of later states): its columns after these, its numbers by the largest.
  // Empty: takes part's names.
  void append(const SchemeState& part) {
    if (columns.empty() && largest.empty()) {
      *this = part;
      return;
    }
    for (std::size_t c = 0; c < columns.size() && c < part.columns.size(); ++c)
      columns[c].values.insert(columns[c].values.end(), part.columns[c].values.begin(), part.columns[c].values.end());
    for (std::size_t l = 0; l < largest.size() && l < part.largest.size(); ++l)
      largest[l].value = std::max(largest[l].value, part.largest[l].value);
  }

  // The state of the states at `indices` (positions in this state's order), with the same run numbers.
  SchemeState select(const std::vector<std::size_t>& indices) const {
    SchemeState part{{}, largest};
    for (const Column& column : columns) {
      Column selected{column.name, column.per_state, {}};
      for (std::size_t index : indices) {
        const auto from = column.values.begin() + static_cast<std::ptrdiff_t>(index * column.per_state);
        selected.values.insert(selected.values.end(), from, from + static_cast<std::ptrdiff_t>(column.per_state));
      }
      part.columns.push_back(std::move(selected));
    }
    return part;
  }
};

// A number a scheme reports about a run (summary.json; Tao: omega and the largest copy distance), with what it
// means when that is not plain from its name. The numbers of a run's parts combine by taking the largest.
struct SchemeFigure {
  std::string name;
  double value = 0.0;
  std::string note;
};

}  // namespace nonsep
