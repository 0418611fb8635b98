// The stepping loop of `motes run` and `motes resume`, in one process and over MPI ranks
// (session_loop.h).
#include "session_loop.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <utility>

#include "cli_util.h"
#include "motes/simulation.h"
#include "render_args.h"

namespace motes::cli {

SessionLoop::SessionLoop(std::vector<double> frame_times, FrameWriter* writer,
                         render::RenderOutput* render, const char* checkpoint_kind)
    : frame_times_(std::move(frame_times)),
      writer_(writer),
      render_(render),
      checkpoint_kind_(checkpoint_kind) {}

void SessionLoop::run_steps(std::uint64_t total, std::uint64_t every,
                            std::uint64_t checkpoint_every, bool resumed) {
  const std::uint64_t first = current_step();
  first_step_ = first;
  const std::uint64_t ck = checkpoint_every;
  if (!resumed) {
    write_frame();
  } else {
    guard_state();  // the checkpoint's state, before the first step
    if (!frame_times_.empty() && frame_times_.back() == current_time()) {
      last_frame_step_ = first;  // the checkpoint's step already has its frame
    }
  }
  std::uint64_t next_frame = (first / every + 1) * every;
  std::uint64_t next_checkpoint =
      ck > 0 ? (first / ck + 1) * ck : std::numeric_limits<std::uint64_t>::max();
  std::uint64_t chunk = 1;
  bool stepped = false;
  double took = 0.0;
  while (current_step() < total) {
    const ChunkStart start = start_chunk(stepped, took);
    if (start.signal != 0) {
      signal_ = start.signal;
      break;
    }
    if (start.resize) {
      if (start.took < kChunkSeconds / 2 && chunk < kMaxChunk) chunk *= 2;
      if (start.took > kChunkSeconds * 2 && chunk > 1) chunk /= 2;
    }
    const std::uint64_t done = current_step();
    // > done: a guard runs at the start and whenever a chunk reaches it.
    const std::uint64_t next_guard = last_guard_step_ + Simulation::kGuardInterval;
    const std::uint64_t n = std::min(
        {chunk, total - done, next_frame - done, next_checkpoint - done, next_guard - done});
    const std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
    step_chunk(n);
    took = seconds_since(t0);
    stepped = true;
    step_seconds_ += took;
    if (current_step() == next_frame) {
      write_frame();
      next_frame += every;
    } else if (current_step() >= next_guard) {
      guard_state();
    }
    if (current_step() == next_checkpoint) {
      // The one at the end comes after the final frame (the caller's).
      if (current_step() < total) save_checkpoint();
      next_checkpoint += ck;
    }
    if (progress_ != nullptr) progress_->update(current_step(), current_time());
  }
  // The final state is always a frame, also when the step count is not a multiple of `every`.
  if (current_step() >= total && last_frame_step_ != current_step()) write_frame();
}

void SessionLoop::note_warning(const std::string& warning, double travel) {
  if (warning.empty()) return;
  ++warned_checks_;
  worst_travel_ = std::max(worst_travel_, travel);
  if (travel > 2.0 * last_warned_travel_) {
    if (progress_ != nullptr) progress_->finish();
    fmt::print(stderr, "motes: warning: {}\n", warning);
    last_warned_travel_ = travel;
  }
}

void SessionLoop::stop(const std::string& message) {
  if (progress_ != nullptr) progress_->finish();
  if (writer_ != nullptr) (void)writer_->finish();
  if (render_ != nullptr) (void)render_->finish();
  fail(fmt::format(
      "{}\nmotes: run stopped; {}; {}", message, frames_written(),
      last_checkpoint_.empty()
          ? fmt::format("no {} was written (--checkpoint-every N keeps one)", checkpoint_kind_)
          : fmt::format("the last good {} is {}", checkpoint_kind_, last_checkpoint_)));
}

std::string SessionLoop::frames_written() const {
  return fmt::format("{} frame{} written{}", frame_times_.size(),
                     frame_times_.size() == 1 ? "" : "s",
                     writer_ != nullptr ? fmt::format(" ({})", writer_->main_path()) : "");
}

void SessionLoop::print_frames() const {
  if (writer_ != nullptr) {
    fmt::print("  {:<16}{} written to {}\n", "frames", writer_->frames(), writer_->main_path());
  } else {
    fmt::print("  {:<16}none written (--format none)\n", "frames");
  }
  if (render_ != nullptr) fmt::print("  {:<16}{}\n", "pictures", render_summary(*render_));
}

void SessionLoop::print_guards(const char* where) const {
  fmt::print(
      "  {:<16}{} motion check{}{}{}; {}\n", "guards", guards_, guards_ == 1 ? "" : "s", where,
      warned_checks_ == 0 ? std::string(", no warning")
                          : fmt::format(", {} with a tunnelling warning (the worst: {:.3g} of a "
                                        "diameter per substep)",
                                        warned_checks_, worst_travel_),
      energy_.summary());
}

}  // namespace motes::cli
