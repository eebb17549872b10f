// Running the compiler under a guard, within a time limit (compiler_process.hpp).
#include "nonsep/host/formula/compiler_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

extern char** environ;

namespace nonsep::host::formula {

namespace {

namespace fs = std::filesystem;

constexpr std::size_t kept_output_bytes = std::size_t{1} << 16;

std::string seconds_text(std::chrono::milliseconds limit) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", static_cast<double>(limit.count()) / 1000.0);
  return text;
}

// Appends what the pipe holds now (non-blocking); false once it is closed or fails.
bool read_available(int descriptor, std::string& output) {
  char buffer[4096];
  for (std::size_t taken = 0; taken < (std::size_t{1} << 20);) {
    const ssize_t n = ::read(descriptor, buffer, sizeof buffer);
    if (n == 0) return false;
    if (n < 0) return errno == EAGAIN || errno == EINTR;
    output.append(buffer, static_cast<std::size_t>(n));
    if (output.size() > kept_output_bytes) output.erase(0, output.size() - kept_output_bytes);
    taken += static_cast<std::size_t>(n);
  }
  return true;
}

int decoded(int wait_status) {
  return WIFSIGNALED(wait_status) ? 128 + WTERMSIG(wait_status) : WEXITSTATUS(wait_status);
}

volatile sig_atomic_t guard_abandoned = 0;
extern "C" void abandon_compile(int) { guard_abandoned = 1; }

}  // namespace

std::chrono::milliseconds compile_time_limit() {
  const char* text = std::getenv(std::string(compile_time_limit_variable).c_str());
  if (!text || !*text) return default_compile_time_limit;
  double seconds = 0.0;
  const char* end = text + std::strlen(text);
  const auto [stop, error] = std::from_chars(text, end, seconds);
  if (error != std::errc() || stop != end || !std::isfinite(seconds) || seconds <= 0.0 || seconds > 1e6)
    throw FormulaCompileError(std::string(compile_time_limit_variable) + " is \"" + text +
                              "\"; allowed: a number of seconds > 0 and <= 1e6 (unset: " +
                              std::to_string(default_compile_time_limit.count()) + ")");
  return std::chrono::milliseconds(static_cast<std::int64_t>(std::ceil(seconds * 1000.0)));
}

CompilerOutcome run_compiler(const std::vector<std::string>& arguments, std::chrono::milliseconds limit,
                             const std::vector<fs::path>& abandon) {
  std::vector<std::string> guard_arguments{"/proc/self/exe", std::string(compiler_guard_argument),
                                           std::to_string(::getpid()), std::to_string(abandon.size())};
  for (const auto& folder : abandon) guard_arguments.push_back(folder.string());
  guard_arguments.insert(guard_arguments.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (auto& argument : guard_arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);

  int pipe_ends[2];
  if (::pipe2(pipe_ends, O_CLOEXEC) != 0)
    throw FormulaCompileError("cannot create a pipe to run the compiler: " + std::string(std::strerror(errno)));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_ends[1], 1);
  posix_spawn_file_actions_adddup2(&actions, pipe_ends[1], 2);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  pid_t guard = 0;
  const int spawned = ::posix_spawn(&guard, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_ends[1]);
  if (spawned != 0) {
    ::close(pipe_ends[0]);
    throw FormulaCompileError("cannot start nonsep's compiler guard (/proc/self/exe): " +
                              std::string(std::strerror(spawned)));
  }
  ::fcntl(pipe_ends[0], F_SETFL, ::fcntl(pipe_ends[0], F_GETFL) | O_NONBLOCK);
  const auto deadline = std::chrono::steady_clock::now() + limit;
  CompilerOutcome outcome;
  bool open = true;
  for (;;) {
    int wait_status = 0;
    const pid_t done = ::waitpid(guard, &wait_status, WNOHANG);
    if (done == guard) {
      if (open) read_available(pipe_ends[0], outcome.output);
      outcome.status = decoded(wait_status);
      break;
    }
    if (std::chrono::steady_clock::now() >= deadline) {
      ::kill(guard, SIGTERM);
      while (::waitpid(guard, &wait_status, 0) < 0 && errno == EINTR) {
      }
      ::close(pipe_ends[0]);
      throw FormulaCompileError(
          "the compiler " + arguments.front() + " did not finish within the compile time limit of " +
          seconds_text(limit) + " s (" + std::string(compile_time_limit_variable) + ", in seconds; default " +
          std::to_string(default_compile_time_limit.count()) + "): it was stopped with all its processes");
    }
    if (open) {
      pollfd readable{pipe_ends[0], POLLIN, 0};
      ::poll(&readable, 1, 50);
      open = read_available(pipe_ends[0], outcome.output);
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  ::close(pipe_ends[0]);
  return outcome;
}

int run_compiler_guard(int argc, char** argv) {
  if (argc < 5) return 127;
  const long parent = std::strtol(argv[2], nullptr, 10);
  const long folders = std::strtol(argv[3], nullptr, 10);
  if (folders < 0 || 4 + folders >= argc) return 127;
  char** compiler = argv + 4 + folders;

  struct sigaction action = {};
  action.sa_handler = abandon_compile;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGTERM, &action, nullptr);
  ::signal(SIGINT, SIG_IGN);
  ::signal(SIGHUP, SIG_IGN);
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (::getppid() != static_cast<pid_t>(parent)) guard_abandoned = 1;  // nonsep died before the request

  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t defaults;
  sigemptyset(&defaults);
  for (int signal : {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGXFSZ}) sigaddset(&defaults, signal);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setpgroup(&attributes, 0);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETPGROUP);
  pid_t child = 0;
  const int spawned = ::posix_spawnp(&child, compiler[0], nullptr, &attributes, compiler, environ);
  posix_spawnattr_destroy(&attributes);
  if (spawned != 0) {
    std::fprintf(stderr, "cannot start %s: %s\n", compiler[0], std::strerror(spawned));
    return 127;
  }
  int wait_status = 0;
  for (;;) {
    if (guard_abandoned) {
      ::kill(-child, SIGKILL);
      while (::waitpid(child, &wait_status, 0) < 0 && errno == EINTR) {
      }
      std::error_code error;
      for (long i = 0; i < folders; ++i) fs::remove_all(argv[4 + i], error);
      return 128 + SIGTERM;
    }
    // Not reaped yet (WNOWAIT): the group's number stays the compiler's while its remains are killed.
    siginfo_t exited = {};
    if (::waitid(P_PID, static_cast<id_t>(child), &exited, WEXITED | WNOHANG | WNOWAIT) == 0 && exited.si_pid == child)
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(-child, SIGKILL);  // what the compiler left running in its group (a background child of a driver)
  while (::waitpid(child, &wait_status, 0) < 0 && errno == EINTR) {
  }
  return decoded(wait_status);
}

}  // namespace nonsep::host::formula
