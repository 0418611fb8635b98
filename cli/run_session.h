// The stepping loop that `motes run` and `motes resume` share: frames, periodic checkpoints,
// progress, SIGINT/SIGTERM, the summary (docs/cli.md, docs/reliability.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "motes/checkpoint.h"
#include "motes/output.h"
#include "motes/render_output.h"
#include "motes/scene.h"
#include "motes/simulation.h"

namespace motes::cli {

/// Everything a session needs, prepared by cmd_run.cpp or cmd_resume.cpp.
struct SessionPlan {
  std::string scene_name;                        ///< for messages
  std::unique_ptr<Simulation> sim;               ///< at its first step (0, or the checkpoint's)
  std::unique_ptr<FrameWriter> writer;           ///< none with --format none
  std::unique_ptr<render::RenderOutput> render;  ///< motes run --render only
  std::uint64_t total = 0;                       ///< the step to stop at
  std::uint64_t every = 1;             ///< a frame at every multiple of it (and at the end)
  std::uint64_t checkpoint_every = 0;  ///< 0: only the last checkpoint of an interrupted run
  /// What every checkpoint records about the run (its series is filled in at each save).
  CheckpointRun record;
  /// A resumed run: the series so far (frames are not written again) and the checkpoint it came
  /// from; frame 0 is not written.
  bool resumed = false;
  double setup_seconds = 0.0;
};

/// SIGINT and SIGTERM while a run goes on (docs/cli.md): from construction to destruction the
/// first one is noted (caught()) instead of ending the process, so that the run stops at a step
/// boundary with a last checkpoint; a second one ends the process at once.
class InterruptSignals {
 public:
  InterruptSignals();
  ~InterruptSignals();
  InterruptSignals(const InterruptSignals&) = delete;
  InterruptSignals& operator=(const InterruptSignals&) = delete;
  /// The signal caught since construction, or 0.
  [[nodiscard]] static int caught();

 private:
  void (*previous_int_)(int) = nullptr;
  void (*previous_term_)(int) = nullptr;
};

/// The energy guard over a run, for the summary's guard line (docs/cli.md): the largest rise of
/// the scene's energy above the guard's reference seen at a check, as a fraction of that check's
/// margin.
class EnergyRise {
 public:
  void add(double rise, double margin);
  /// "energy at most 0.012 of its margin above its start (1.2e-05 J of 0.00098 J)", "energy never
  /// above its start (margin 0.00098 J)", or "no energy check".
  [[nodiscard]] std::string summary() const;

 private:
  bool any_ = false;
  double fraction_ = 0.0;
  double rise_ = 0.0;
  double margin_ = 0.0;
};

/// "SIGINT (Ctrl-C)", "SIGTERM".
const char* signal_name(int signal);

/// Checkpoint files in a directory: checkpoint-<step, 12 digits>.mck, the last two kept.
std::string checkpoint_file_name(std::uint64_t step);

/// Runs the plan to its end or to SIGINT/SIGTERM and prints the summary; exits through
/// CLI::RuntimeError with 128 + the signal's number after a signal, through fail() on errors.
void run_session(SessionPlan plan);

/// After checkpoint `newest` (PREFIX<step>SUFFIX in `dir`, files, or directories for the sets
/// of a run over MPI ranks) is in place: keeps it and the newest older one, removes the other
/// older ones and what kills left of writes (SUFFIX.tmp). Later ones (of a run this one was
/// resumed from an earlier point of) and entries of the other kind are left alone.
void prune_numbered(const std::filesystem::path& dir, std::uint64_t newest,
                    const std::string& prefix, const std::string& suffix, bool directories);

}  // namespace motes::cli
