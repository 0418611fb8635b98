// The stepping loop that a run in one process (run_session.cpp) and a run over MPI ranks
// (run_mpi_session.cpp) share: frame 0 or the resumed state's guard, chunks of steps sized to
// take about kChunkSeconds, a frame every K steps, a guard at least every
// Simulation::kGuardInterval steps, a checkpoint every C steps, progress and the final frame; with
// what both do with the guard's tunnelling warnings and with a run that cannot go on.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "motes/output.h"
#include "motes/render_output.h"
#include "progress.h"
#include "run_session.h"

namespace motes::cli {

class SessionLoop {
 public:
  virtual ~SessionLoop() = default;
  SessionLoop(const SessionLoop&) = delete;
  SessionLoop& operator=(const SessionLoop&) = delete;

 protected:
  /// `frame_times`: the series so far (a resumed run's); `writer` and `render`: the run's, or
  /// null (none, or not this rank's); `checkpoint_kind`: "checkpoint" or "checkpoint set", for
  /// messages.
  SessionLoop(std::vector<double> frame_times, FrameWriter* writer, render::RenderOutput* render,
              const char* checkpoint_kind);

  /// At the start of every chunk: the signal to stop at (0: go on), and whether to size the next
  /// chunk by `took` seconds.
  struct ChunkStart {
    int signal = 0;
    double took = 0.0;
    bool resize = false;
  };

  /// The state's step and simulated time.
  [[nodiscard]] virtual std::uint64_t current_step() const = 0;
  [[nodiscard]] virtual double current_time() const = 0;
  /// Before a chunk: `stepped` is false before the first one, `took` the last one's seconds.
  virtual ChunkStart start_chunk(bool stepped, double took) = 0;
  /// Runs `n` steps (errors end the run).
  virtual void step_chunk(std::uint64_t n) = 0;
  /// The motion guard on the state (sets last_guard_step_).
  virtual void guard_state() = 0;
  /// The guard, then the state as the next frame (adds to frame_times_, sets last_frame_step_).
  virtual void write_frame() = 0;
  /// A checkpoint of the state (sets last_checkpoint_, counts checkpoints_).
  virtual void save_checkpoint() = 0;

  /// Frame 0 (not for a resumed run), the steps to `total` with a frame every `every` steps and a
  /// checkpoint every `checkpoint_every` (0: none), progress_ updated after every chunk, and the
  /// final state as a frame. A signal ends it early (signal_); the checkpoint at the end is the
  /// caller's.
  void run_steps(std::uint64_t total, std::uint64_t every, std::uint64_t checkpoint_every,
                 bool resumed);

  /// A guard's tunnelling warning (empty: none) at `travel` diameters per substep: counted, and
  /// printed the first time and whenever it is twice as bad as the last one printed.
  void note_warning(const std::string& warning, double travel);

  /// Ends a run that cannot go on: the frames so far are finished (their series stays
  /// readable), the message says which checkpoint is the last good one, the exit is non-zero.
  [[noreturn]] void stop(const std::string& message);

  /// "3 frames written (out/frames.pvd)".
  [[nodiscard]] std::string frames_written() const;

  /// The summary's frames and pictures lines.
  void print_frames() const;
  /// The summary's guards line; `where`: what the checks ran on (" on the gathered state"), or
  /// empty.
  void print_guards(const char* where) const;

  std::vector<double> frame_times_;
  std::uint64_t first_step_ = 0;
  std::uint64_t last_frame_step_ = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t checkpoints_ = 0;
  std::string last_checkpoint_;
  Progress* progress_ = nullptr;  // while the loop runs (over ranks: rank 0's)
  std::uint64_t last_guard_step_ = 0;
  std::uint64_t guards_ = 0;
  std::uint64_t warned_checks_ = 0;
  double worst_travel_ = 0.0;
  double last_warned_travel_ = 0.0;
  EnergyRise energy_;
  int signal_ = 0;
  double wall_seconds_ = 0.0;
  double step_seconds_ = 0.0;
  double output_seconds_ = 0.0;

 private:
  FrameWriter* writer_;
  render::RenderOutput* render_;
  const char* checkpoint_kind_;
};

}  // namespace motes::cli
