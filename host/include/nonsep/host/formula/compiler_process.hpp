#pragma once
// Running the C++ compiler for a formula model: bounded in time, and never leaving a process or a folder behind.
//
// The compiler does not run as a child of nonsep but of a guard: nonsep starts its own executable
// (/proc/self/exe) with compiler_guard_argument, and that guard starts the compiler (posix_spawnp, no shell) in a
// process group of its own. The guard
//   - asks the kernel for SIGTERM when its parent thread ends (PR_SET_PDEATHSIG): when nonsep dies, however (SIGINT,
//     SIGTERM and SIGHUP at their default disposition during a compile, SIGKILL, a crash), the guard kills the
//     compiler's whole process group with SIGKILL and removes the folders it was given (the compile's work folder),
//     then exits; a SIGTERM from nonsep (the time limit) does the same;
//   - ignores SIGINT and SIGHUP itself (the terminal's ^C reaches nonsep, whose death ends the guard), and gives the
//     compiler the default disposition of every signal nonsep ignores (SIGPIPE, SIGXFSZ);
//   - when the compiler exits, kills what is left of its process group (a background child of a compiler driver)
//     and exits with the compiler's status (128 + n when it was killed by signal n).
// nonsep reads the compiler's standard output and error (one pipe) until the guard exits, not until the pipe is
// closed: a child that left the group and holds the pipe cannot keep it waiting. PR_SET_PDEATHSIG follows the
// thread that started the guard, so run_compiler is called from the thread that lives as long as the compile
// (the main thread, in nonsep).
//
// The time limit: NONSEP_COMPILE_TIME_LIMIT seconds (a number > 0), default_compile_time_limit when unset. It
// bounds every run of the compiler (`--version` too); at the limit the compiler's group is killed and
// FormulaCompileError names the compiler and the limit.
#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace nonsep::host::formula {

class FormulaCompileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr std::chrono::seconds default_compile_time_limit{300};
inline constexpr std::string_view compile_time_limit_variable = "NONSEP_COMPILE_TIME_LIMIT";

// The limit from NONSEP_COMPILE_TIME_LIMIT; throws FormulaCompileError naming the variable when it is not a number
// of seconds > 0.
std::chrono::milliseconds compile_time_limit();

struct CompilerOutcome {
  int status = 0;      // the compiler's exit status, 128 + n when killed by signal n, 127 when it could not start
  std::string output;  // its standard output and error together, at most the last 64 KiB
};

// Runs `arguments` (argv[0] a path or a name looked up in PATH) through the guard within `limit`; `abandon` lists
// folders the guard removes when nonsep dies or the limit is reached. Throws FormulaCompileError at the limit
// (naming arguments[0] and the limit) or when the guard cannot start.
CompilerOutcome run_compiler(const std::vector<std::string>& arguments, std::chrono::milliseconds limit,
                             const std::vector<std::filesystem::path>& abandon = {});

// The first argument that makes the executable the guard (main() checks for it before anything else), and the
// guard itself: argv = {exe, compiler_guard_argument, parent pid, folder count, folders..., compiler argv...}.
inline constexpr std::string_view compiler_guard_argument = "--nonsep-internal-compiler-guard";
int run_compiler_guard(int argc, char** argv);

}  // namespace nonsep::host::formula
