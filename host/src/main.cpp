// The nonsep executable. Everything happens in nonsep_host (command_line.hpp), which the tests also use.
#include <csignal>
#include <iostream>
#include <string_view>

#include "nonsep/host/command_line.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/formula/compiler_process.hpp"

int main(int argc, char** argv) {
  // The process between nonsep and a formula model's compiler (compiler_process.hpp), started by nonsep itself.
  if (argc > 1 && std::string_view(argv[1]) == nonsep::host::formula::compiler_guard_argument)
    return nonsep::host::formula::run_compiler_guard(argc, argv);
  // A closed standard output (`nonsep models | head -1`) is a write error reported below, not a death by SIGPIPE
  // with a status outside the documented table.
  std::signal(SIGPIPE, SIG_IGN);
  // Likewise a file size limit (`ulimit -f`): write() fails with EFBIG, which the run reports (exit 1, the file cut
  // back to its last whole row, summary.json written), instead of a death by SIGXFSZ halfway through a row.
  std::signal(SIGXFSZ, SIG_IGN);
  const int status = nonsep::host::run_command_line(argc, argv);
  if (!std::cout.flush()) {
    std::cerr << "nonsep: cannot write to standard output (was it closed?)\n";
    return status == 0 ? nonsep::host::to_int(nonsep::host::ExitStatus::run_failed) : status;
  }
  return status;
}
