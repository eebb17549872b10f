#include "nonsep/host/observers/progress_bar.hpp"

#include <unistd.h>

#include <cstdio>

namespace nonsep::host {

bool stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

ProgressBar::ProgressBar(bool enabled, std::uint64_t total_steps)
    : enabled_(enabled), total_(total_steps), start_(Clock::now()), next_draw_(start_ + std::chrono::seconds(1)) {}

void ProgressBar::update(std::uint64_t step, double t, std::size_t active_trajectories,
                         std::optional<double> largest_energy_error) {
  if (!enabled_) return;
  const auto now = Clock::now();
  if (now < next_draw_) return;
  next_draw_ = now + std::chrono::milliseconds(100);
  const double fraction = total_ ? static_cast<double>(step) / static_cast<double>(total_) : 1.0;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double remaining = fraction > 0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  constexpr int width = 30;
  char bar[width + 1];
  const int filled = static_cast<int>(fraction * width);
  for (int i = 0; i < width; ++i) bar[i] = i < filled ? '#' : '.';
  bar[width] = '\0';
  char energy[48] = "";
  if (largest_energy_error) std::snprintf(energy, sizeof energy, "  max |dH/H0| %.2e", *largest_energy_error);
  std::fprintf(stderr, "\r[%s] %5.1f%%  step %llu/%llu  t = %.6g  %zu active%s  %.0f s left \033[K", bar,
               100.0 * fraction, static_cast<unsigned long long>(step), static_cast<unsigned long long>(total_), t,
               active_trajectories, energy, remaining);
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (!drawn_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace nonsep::host
