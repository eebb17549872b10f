#pragma once
// SIGINT, SIGTERM and SIGUSR1 during `nonsep run` (run_command.cpp): the first stops the run, which finishes its step,
// flushes its files and writes its checkpoint and summary (RunOptions::stop_requested); the same signal delivered
// twice within a second is one request; any of them again later ends the process at once.
#include <atomic>
#include <csignal>

namespace nonsep::host::cli {

// Set by the first stopping signal while an InterruptGuard is in place; a run reads it between chunks.
std::atomic<bool>& stop_requested();
// The first stopping signal (SIGINT, SIGTERM or SIGUSR1), 0 before any.
int stop_signal();
// Forgets an earlier request, before a run starts.
void reset_stop_request();
// "SIGINT", "SIGTERM" or "SIGUSR1", for messages.
const char* signal_name(int signal);

// Catches SIGINT, SIGTERM and SIGUSR1: the first stops the run (it finishes its step, flushes trajectory.csv and
// writes its checkpoint and summary). Any of them again, more than repeat_window_nanoseconds after the first, ends
// the process at once; earlier it is taken for the same request delivered twice and ignored. No SA_RESTART: a
// plugin sleeping or waiting in a system call sees EINTR and returns sooner.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct sigaction previous_interrupt_ = {}, previous_terminate_ = {}, previous_user1_ = {};
};

}  // namespace nonsep::host::cli
