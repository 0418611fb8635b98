// `motes run` under mpirun (cmd_run_mpi.cpp, docs/scale-out.md): MPI's start and end, and the
// run over several ranks.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "motes/output.h"
#include "motes/scene.h"

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
  double setup_seconds = 0.0;
};

/// Runs the scene over every rank; rank 0 gathers and writes the frames and prints the summary.
/// Errors end every rank through fail() (printed once, by rank 0).
void run_distributed(DistributedRun run);

}  // namespace motes::cli
