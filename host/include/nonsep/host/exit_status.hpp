#pragma once
// The exit statuses of the `nonsep` executable. They are part of its interface: scripts and schedulers rely on
// them, `nonsep --help` and docs/user-guide.md list them.
namespace nonsep::host {

enum class ExitStatus : int {
  success = 0,        // the command did what was asked (every trajectory completed, the job is valid, ...)
  run_failed = 1,     // a run started but did not complete: a trajectory diverged, the plugin failed mid-run,
                      // a trajectory was retired as inaccurate (analysis.max_relative_energy_error), an output
                      // could not be written; `inspect --check` found wrong derivatives
  invalid_input = 2,  // nothing was run: bad usage, an invalid job file or parameters, a plugin that cannot load
  interrupted = 130,  // SIGINT: the current step was finished and the outputs written with status "interrupted"
  terminated = 143,   // SIGTERM (or SIGUSR1, which mpirun passes on): the same as SIGINT (128 + 15, as a shell
                      // reports SIGTERM)
};

constexpr int to_int(ExitStatus status) { return static_cast<int>(status); }

}  // namespace nonsep::host
