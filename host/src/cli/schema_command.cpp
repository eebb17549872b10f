// `nonsep schema`: the JSON Schema of job files (job_schema.hpp) on stdout; schemas/job.schema.json is this output.
#include <iostream>

#include "cli/commands.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/job_schema.hpp"

namespace nonsep::host::cli {

int command_schema() {
  std::cout << job_schema().dump(2) << "\n";
  return to_int(ExitStatus::success);
}

}  // namespace nonsep::host::cli
