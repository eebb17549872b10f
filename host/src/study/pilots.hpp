#pragma once
// Scheme "auto"'s pilots (the rules are in scheme_choice.hpp): up to auto_pilot_states of the job's states stepped
// to the pilot horizon t_end / fraction by each candidate at n, 2n and 4n steps until the ladder is asymptotic,
// and the step and cost predicted from it.
#include <cstddef>
#include <vector>

#include "nonsep/host/job.hpp"
#include "nonsep/host/launch/run_job.hpp"
#include "nonsep/host/study/scheme_choice.hpp"

namespace nonsep::host {

// Measures every candidate of the job (auto_candidates) to t_end / fraction: sets choice.pilots (one PilotResult
// each, in candidate order), pilot_states and pilot_horizon, and adds the pilots' time, state steps and evaluations
// to choice. A candidate whose pilots would take longer than the least predicted run before it is left out with the
// reason. Throws PilotsInterrupted when options.stop_requested is set during a pilot.
// The pilot states (indices into the job's states, increasing): up to auto_pilot_states of them, evenly spread, the
// first and the last of each set among them; with a sweep, of every parameter set's states alike, at least one each,
// so that the choice meets the tolerance on every set.
std::vector<std::size_t> pilot_indices(const InitialStates& initial);

void run_pilots(const LoadedJob& loaded, const RunOptions& options, SchemeChoice& choice, double fraction);

}  // namespace nonsep::host
