// Progress lines of `motes run`.
#include "progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "cli_util.h"

namespace motes::cli {

namespace {
// A terminal line is redrawn at most this often (seconds).
constexpr double kRedrawInterval = 0.25;
}  // namespace

Progress::Progress(std::uint64_t total_steps, std::uint64_t first_step)
    : total_(total_steps),
      first_(first_step),
      terminal_(isatty(fileno(stderr)) != 0),
      start_(std::chrono::steady_clock::now()) {}

double Progress::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::update(std::uint64_t step, double time) {
  // The summary reports the end; a progress line there would only repeat it.
  if (step >= total_) return;
  if (terminal_) {
    const double now = elapsed();
    if (now - last_print_ >= kRedrawInterval) {
      last_print_ = now;
      print(step, time, true);
    }
    return;
  }
  // Logs: one line each time another tenth of the run is done (not for the last: the summary).
  bool due = false;
  while (next_tenth_ < 10 &&
         static_cast<double>(step) * 10.0 >= static_cast<double>(total_) * next_tenth_) {
    ++next_tenth_;
    due = true;
  }
  if (due) print(step, time, false);
}

void Progress::print(std::uint64_t step, double time, bool rewrite) {
  const double wall = elapsed();
  const double fraction = static_cast<double>(step) / static_cast<double>(total_);
  const double rate = wall > 0.0 && step > first_ ? static_cast<double>(step - first_) / wall : 0.0;
  const std::string eta =
      rate > 0.0 ? format_seconds(static_cast<double>(total_ - step) / rate) : "?";
  const std::string line = fmt::format("step {}/{}  t = {:.4g} s  {:.0f}%  {} steps/s  ETA {}",
                                       step, total_, time, fraction * 100.0, format_si(rate), eta);
  if (rewrite) {
    // \033[K clears what a longer previous line left behind.
    fmt::print(stderr, "\r{}\033[K", line);
    drawn_ = true;
  } else {
    fmt::print(stderr, "motes: {}\n", line);
  }
  std::fflush(stderr);
}

void Progress::finish() {
  if (drawn_) {
    fmt::print(stderr, "\r\033[K");
    std::fflush(stderr);
    drawn_ = false;
  }
}

}  // namespace motes::cli
