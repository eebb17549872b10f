#pragma once
// What `nonsep run` says at the end (run_command.cpp): the run's or the study's line, the trajectories that stopped
// early (up to a screenful), warnings, and the exit status.
#include <filesystem>

#include "cli/commands.hpp"
#include "nonsep/host/launch/run_job.hpp"
#include "nonsep/host/study/convergence_study.hpp"

namespace nonsep::host::cli {

// The end of a study: one line per integrator with its fitted exponent, or what went wrong; then warnings about fits
// that round-off or a sign change make unreliable (on stderr, also with --quiet). Returns the exit status.
int report_study(const StudyOutcome& outcome, const std::filesystem::path& directory, bool quiet);

// The end of a run: its line (stdout on success unless --quiet, stderr otherwise), how to resume it after `signal`
// stopped it, its notes, the trajectories that stopped early and the warnings. Returns the exit status.
int report_run(const RunOutcome& outcome, const Job& job, const RunArguments& arguments,
               const std::filesystem::path& directory, int signal);

}  // namespace nonsep::host::cli
