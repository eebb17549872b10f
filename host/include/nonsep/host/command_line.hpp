#pragma once
// The `nonsep` command line: run, validate, inspect, models, schema, --version (CLI11). main() is a call to this.
namespace nonsep::host {

// Parses argv, runs the command and returns the process exit status (exit_status.hpp): 0, 1, 2, 130 or 143.
// Prints results on stdout and diagnostics on stderr. Never throws: every exception becomes a message and a
// status. Installs SIGINT and SIGTERM handlers for the duration of `nonsep run`.
int run_command_line(int argc, char** argv);

}  // namespace nonsep::host
