// `motes run` under mpirun (cmd_run_mpi.cpp, docs/scale-out.md): MPI's start and end, and the
// run over several ranks.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "motes/checkpoint.h"
#include "motes/output.h"
#include "motes/scene.h"
#include "render_args.h"

namespace motes::cli {

/// Starts MPI when this process was launched by mpirun/mpiexec (OpenMPI, MPICH or a PMIx
/// launcher), and ends it when destroyed. A binary built without MPI that finds itself launched
/// as one of several ranks says so and exits, instead of running the scene N times over.
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
};

/// The number of MPI ranks of this run (1 without mpirun) and this process's rank.
int mpi_ranks();
int mpi_rank();

/// Collective under MPI: fail() on every rank when any rank's `mine` is an error (the lowest
/// failing rank's message, printed once); without MPI, fail() on an error.
void mpi_agree_or_fail(const Status& mine);

/// What `motes run` passes on to a run over several ranks.
struct DistributedRun {
  Scene scene;
  std::string scene_name;
  std::string backend = "auto";
  int device = -1;  ///< -1: the rank's index among the ranks on its host
  int threads = 0;
  std::uint64_t total = 0;
  std::uint64_t every = 1;
  OutputFormat format = OutputFormat::Vtu;
  std::string out;
  std::optional<std::array<int, 3>> decomposition;
  /// --halo host: the halo copies through host memory always (DistributedOptions::Halo::Host).
  bool halo_host = false;
  double setup_seconds = 0.0;
  /// A checkpoint set every K steps and at the end (0: only when a signal stops the run).
  std::uint64_t checkpoint_every = 0;
  /// What every set records about the run (rank 0 fills in the series at each set).
  CheckpointRun record;
  /// --render DIR (empty: no pictures) and its options: rank 0 draws the gathered frames.
  std::string render_dir;
  RenderArgs render;
};

/// Runs the scene over every rank; rank 0 gathers and writes the frames and prints the summary.
/// Errors end every rank through fail() (printed once, by rank 0).
void run_distributed(DistributedRun run);

/// What `motes resume` passes on to a resume of a checkpoint set (or, under mpirun, of anything).
struct DistributedResume {
  std::string path;     ///< the set (a directory), or a file that is refused with the reason
  std::string backend;  ///< empty: the set's
  int device = -1;
  int threads = 0;
  std::optional<std::uint64_t> steps;
  std::optional<double> duration;
  std::optional<std::uint64_t> checkpoint_every;
  bool halo_host = false;  ///< --halo host
};

/// `mpirun -np N motes resume SET`: goes on with the run of a checkpoint set over the rank count
/// that wrote it. A set of another rank count, a single process's checkpoint under several ranks
/// and one rank's file of a set are refused with the command that would resume them.
void resume_distributed(const DistributedResume& resume);

/// The refusal of `motes resume` for one rank's file of a checkpoint set (a checkpoint whose run
/// record has an extension): names the set and the command that resumes it.
std::string rank_file_refusal(const std::string& path);

}  // namespace motes::cli
