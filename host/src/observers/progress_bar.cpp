#include "nonsep/host/observers/progress_bar.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <utility>

namespace nonsep::host {

bool stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

ProgressBar::ProgressBar(ProgressStyle style, std::uint64_t total_steps, double t_end, double interval_seconds,
                         std::string label, std::shared_ptr<ProgressSchedule> schedule)
    : style_(style),
      total_(total_steps),
      t_end_(t_end),
      interval_(std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(style == ProgressStyle::lines ? interval_seconds : 0.1))),
      start_(Clock::now()),
      label_(std::move(label)),
      schedule_(schedule ? std::move(schedule)
                         : std::make_shared<ProgressSchedule>(ProgressSchedule{
                               start_ + (style == ProgressStyle::lines ? interval_ : std::chrono::seconds(1))})) {}

double remaining_seconds(double elapsed, std::uint64_t start_step, std::uint64_t step, std::uint64_t total) {
  if (step <= start_step) return 0.0;
  return elapsed * static_cast<double>(total > step ? total - step : 0) / static_cast<double>(step - start_step);
}

std::string energy_error_text(std::optional<double> largest, const char* separator) {
  if (!largest) return "";
  if (std::isnan(*largest)) return std::string(separator) + "max |dH/H0| n/a";
  char text[48];
  std::snprintf(text, sizeof text, "%smax |dH/H0| %.2e", separator, *largest);
  return text;
}

void ProgressBar::start_from(std::uint64_t step) {
  start_step_ = step;
  start_ = Clock::now();
}

void ProgressBar::update(std::uint64_t step, double t, std::size_t active_trajectories,
                         std::optional<double> largest_energy_error) {
  if (style_ == ProgressStyle::none) return;
  const auto now = Clock::now();
  if (now < schedule_->next_line) return;
  schedule_->next_line = now + interval_;
  const double fraction = total_ ? static_cast<double>(step) / static_cast<double>(total_) : 1.0;
  const double remaining =
      remaining_seconds(std::chrono::duration<double>(now - start_).count(), start_step_, step, total_);
  if (style_ == ProgressStyle::lines) {
    const std::string energy = energy_error_text(largest_energy_error, ", ");
    std::fprintf(stderr, "nonsep: progress: %s%st = %.6g of %.6g (%.1f%%), step %llu/%llu, %zu active%s, ETA %.0f s\n",
                 label_.c_str(), label_.empty() ? "" : ": ", t, t_end_, 100.0 * fraction,
                 static_cast<unsigned long long>(step), static_cast<unsigned long long>(total_), active_trajectories,
                 energy.c_str(), remaining);
    std::fflush(stderr);
    return;
  }
  constexpr int width = 30;
  char bar[width + 1];
  const int filled = static_cast<int>(fraction * width);
  for (int i = 0; i < width; ++i) bar[i] = i < filled ? '#' : '.';
  bar[width] = '\0';
  const std::string energy = energy_error_text(largest_energy_error, "  ");
  std::fprintf(stderr, "\r[%s] %5.1f%%  step %llu/%llu  t = %.6g  %zu active%s  %.0f s left \033[K", bar,
               100.0 * fraction, static_cast<unsigned long long>(step), static_cast<unsigned long long>(total_), t,
               active_trajectories, energy.c_str(), remaining);
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
