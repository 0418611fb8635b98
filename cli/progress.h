// Progress of `motes run` on stderr: a line rewritten in place on a terminal, a plain line every
// 10% otherwise (logs).
#pragma once

#include <chrono>
#include <cstdint>

namespace motes::cli {

class Progress {
 public:
  /// A run from step `first_step` (a resumed run's) to `total_steps`.
  explicit Progress(std::uint64_t total_steps, std::uint64_t first_step = 0);

  /// Reports that `step` steps are done, at simulated time `time`; prints when due.
  void update(std::uint64_t step, double time);
  /// Clears the terminal line, if one was drawn.
  void finish();

 private:
  [[nodiscard]] double elapsed() const;
  void print(std::uint64_t step, double time, bool rewrite);

  std::uint64_t total_;
  std::uint64_t first_;
  bool terminal_;
  bool drawn_ = false;
  int next_tenth_ = 1;
  std::chrono::steady_clock::time_point start_;
  double last_print_ = 0.0;
};

}  // namespace motes::cli
