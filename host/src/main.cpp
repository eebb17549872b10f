// The nonsep executable. Everything happens in nonsep_host (command_line.hpp), which the tests also use.
#include "nonsep/host/command_line.hpp"

int main(int argc, char** argv) { return nonsep::host::run_command_line(argc, argv); }
