// The stopping signals of `nonsep run` (stop_signals.hpp).
#include "cli/stop_signals.hpp"

#include <time.h>

#include <cstdint>

namespace nonsep::host::cli {

namespace {

std::atomic<bool> stop_requested_flag{false};
std::atomic<int> stop_signal_number{0};
std::atomic<std::int64_t> first_stop_nanoseconds{0};  // CLOCK_MONOTONIC of the first stopping signal
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free &&
                  std::atomic<std::int64_t>::is_always_lock_free,
              "the stop flags must be lock-free to be set in a signal handler");

// A second signal this soon after the first is the same request delivered twice, not the user insisting:
// `timeout` signals the process and then its process group (the process again), mpirun may pass a signal on more
// than once, and a scheduler signals every process of the job.
constexpr std::int64_t repeat_window_nanoseconds = 1'000'000'000;

std::int64_t monotonic_nanoseconds() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);  // async-signal-safe
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

extern "C" void request_stop(int signal) {
  const std::int64_t now = monotonic_nanoseconds();
  std::int64_t first = 0;
  if (first_stop_nanoseconds.compare_exchange_strong(first, now)) {
    stop_signal_number.store(signal);
    stop_requested_flag.store(true);
    return;
  }
  if (now - first < repeat_window_nanoseconds) return;
  // The user insists: the signal's default action (the process ends at once, killed by it), delivered when this
  // handler returns, the signal being blocked while it runs.
  struct sigaction default_action = {};
  default_action.sa_handler = SIG_DFL;
  sigemptyset(&default_action.sa_mask);
  ::sigaction(signal, &default_action, nullptr);
  ::raise(signal);
}

}  // namespace

std::atomic<bool>& stop_requested() { return stop_requested_flag; }
int stop_signal() { return stop_signal_number.load(); }
void reset_stop_request() {
  stop_requested_flag.store(false);
  stop_signal_number.store(0);
  first_stop_nanoseconds.store(0);
}
const char* signal_name(int signal) { return signal == SIGTERM ? "SIGTERM" : signal == SIGUSR1 ? "SIGUSR1" : "SIGINT"; }

InterruptGuard::InterruptGuard() {
  struct sigaction action = {};
  action.sa_handler = request_stop;
  sigemptyset(&action.sa_mask);
  for (int signal : {SIGINT, SIGTERM, SIGUSR1}) sigaddset(&action.sa_mask, signal);
  action.sa_flags = 0;
  sigaction(SIGINT, &action, &previous_interrupt_);
  sigaction(SIGTERM, &action, &previous_terminate_);
  // mpirun passes SIGUSR1 on to every rank (SIGTERM and SIGINT it does not), and Slurm's --signal=USR1@SECONDS
  // warns a job with it before its time is up: it stops a run as SIGTERM does (docs/cluster.md).
  sigaction(SIGUSR1, &action, &previous_user1_);
}
InterruptGuard::~InterruptGuard() {
  sigaction(SIGINT, &previous_interrupt_, nullptr);
  sigaction(SIGTERM, &previous_terminate_, nullptr);
  sigaction(SIGUSR1, &previous_user1_, nullptr);
}

}  // namespace nonsep::host::cli
