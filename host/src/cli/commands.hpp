#pragma once
// Internal to the command line: one function per command (each in its own file), and what they share.
#include <atomic>
#include <string>

#include "nonsep/host/job.hpp"
#include "nonsep/host/time_grid.hpp"

namespace nonsep::host::cli {

struct RunArguments {
  std::string job_file, output;
  bool quiet = false, resume = false, force = false;
  unsigned threads = 0;
};

int command_run(const RunArguments& arguments);
int command_validate(const std::string& job_file);
int command_inspect(const std::string& name, bool as_json, bool check);
int command_models();
int command_schema();

// Texts of --help, generated from the scheme catalogue and the exit statuses.
std::string exit_status_text();
std::string schemes_text();

// "nonsep: <every issue>" on stderr; returns the invalid-input status.
int report_invalid_job(const InvalidJob& error);
// "78 steps of dt = 0.005 to t_end = 0.386... (dt requested ...)".
std::string time_text(const TimeGrid& time);

}  // namespace nonsep::host::cli
