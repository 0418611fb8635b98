// The stepping loop that `motes run` and `motes resume` share over MPI ranks (docs/scale-out.md,
// docs/reliability.md): frames gathered and written by rank 0, pictures, checkpoint sets,
// SIGINT/SIGTERM agreed on by every rank, progress and the summary. Only in a build with MPI.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "motes/checkpoint.h"
#include "motes/distributed.h"
#include "motes/output.h"
#include "motes/render_output.h"

namespace motes::cli {

/// Everything a session over ranks needs, prepared by run_distributed() or resume_distributed().
/// The writer and the pictures exist on rank 0 only.
struct DistributedPlan {
  std::unique_ptr<DistributedSimulation> sim;  ///< at its first step (0, or the set's)
  std::string scene_name;
  std::unique_ptr<FrameWriter> writer;           ///< rank 0; none with --format none
  std::unique_ptr<render::RenderOutput> render;  ///< rank 0; motes run --render only
  std::uint64_t total = 0;                       ///< the step to stop at
  std::uint64_t every = 1;                       ///< a frame at every multiple (and at the end)
  std::uint64_t checkpoint_every = 0;            ///< 0: only the last set of an interrupted run
  /// What every set records about the run (its series is filled in at each set).
  CheckpointRun record;
  /// A resumed run: frame 0 is not written, the frames before the set are in record.series.
  bool resumed = false;
  double setup_seconds = 0.0;
};

/// Checkpoint sets in a directory: checkpoint-<step, 12 digits>.mckset, the last two kept.
std::string checkpoint_set_name(std::uint64_t step);

/// Runs `work` on rank 0 only; a fail() there (printed by rank 0) ends every rank with it.
void on_rank0(const std::function<void()>& work);

/// Runs the plan to its end or to SIGINT/SIGTERM on any rank and prints the summary (rank 0);
/// exits through CLI::RuntimeError with 128 + the signal's number after a signal, through fail()
/// on errors, on every rank alike.
void run_distributed_session(DistributedPlan plan);

}  // namespace motes::cli
