// W1 over MPI ranks (docs/scale-out.md, docs/benchmarks.md "Scale-out"): the falling phase of
// settle_workload at a docs/benchmarks.md size, stepped over every rank of mpirun; rank 0 prints
// one JSON line: ms per step and the slowest rank's seconds per part (its own steps, halo copies,
// MPI, partitions), halo copies at the end, how they travelled (device to device, or through host
// memory) and the setup's seconds (scene and first partition).
// Usage: mpirun -np N motes_mpi_bench [--backend B] [--size N] [--steps S] [--warmup W]
//                                     [--margin M] [--halo auto|host]
#include <fmt/format.h>
#include <mpi.h>

#include <chrono>
#include <cstdlib>
#include <string>

#include "motes/devices.h"
#include "motes/distributed.h"
#include "motes/workloads.h"

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0;
  int ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  std::string backend = "openmp";
  std::uint64_t size = 1048576;
  std::uint64_t steps = 200;
  std::uint64_t warmup = 20;
  motes::DistributedOptions
      options;  // --margin M: the partition margin (m); default half a diameter
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const std::string value = argv[i + 1];
    if (key == "--backend") {
      backend = value;
    } else if (key == "--size") {
      size = std::stoull(value);
    } else if (key == "--steps") {
      steps = std::stoull(value);
    } else if (key == "--warmup") {
      warmup = std::stoull(value);
    } else if (key == "--margin") {
      options.margin = std::stod(value);
    } else if (key == "--halo" && (value == "auto" || value == "host")) {
      options.halo = value == "host" ? motes::DistributedOptions::Halo::Host
                                     : motes::DistributedOptions::Halo::Auto;
    } else {
      if (rank == 0) fmt::print(stderr, "mpi_bench: unknown option {} {}\n", key, value);
      MPI_Finalize();
      return 2;
    }
  }
  int nx = 0, ny = 0, nz = 0;
  if (!motes::settle_dimensions(size, nx, ny, nz)) {
    if (rank == 0) fmt::print(stderr, "mpi_bench: {} is not a W1 size\n", size);
    MPI_Finalize();
    return 2;
  }
  // One GPU per rank: the rank's index on its host, modulo the backend's devices.
  const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_RANK");
  int device = -1;
  for (const motes::BackendReport& r : motes::list_backends()) {
    if (r.backend == backend && backend != "openmp" && local != nullptr && !r.devices.empty()) {
      device = std::atoi(local) % static_cast<int>(r.devices.size());
    }
  }
  motes::DeviceOpener opener = [&]() { return motes::open_device(backend, device); };
  const auto setup_start = std::chrono::steady_clock::now();
  auto sim = motes::DistributedSimulation::create(motes::settle_workload(nx, ny, nz),
                                                  MPI_COMM_WORLD, opener, options);
  if (!sim) {
    if (rank == 0) fmt::print(stderr, "mpi_bench: {}\n", sim.message());
    MPI_Finalize();
    return 2;
  }
  MPI_Barrier(MPI_COMM_WORLD);
  const double setup =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();
  motes::Status s = sim.value()->step(warmup);
  const motes::DistributedStats before = sim.value()->stats();
  MPI_Barrier(MPI_COMM_WORLD);
  const auto start = std::chrono::steady_clock::now();
  if (s) s = sim.value()->step(steps);
  MPI_Barrier(MPI_COMM_WORLD);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!s) {
    if (rank == 0) fmt::print(stderr, "mpi_bench: {}\n", s.message());
    MPI_Finalize();
    return 2;
  }
  const motes::DistributedStats after = sim.value()->stats();
  const double mine[4] = {
      after.step_seconds - before.step_seconds, after.copy_seconds - before.copy_seconds,
      after.mpi_seconds - before.mpi_seconds, after.partition_seconds - before.partition_seconds};
  double most[4] = {0, 0, 0, 0};
  MPI_Reduce(mine, most, 4, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  const std::uint64_t halo = after.halo_particles;
  std::uint64_t halo_total = 0;
  MPI_Reduce(&halo, &halo_total, 1, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
  if (rank == 0) {
    const double per = 1e3 / static_cast<double>(steps);
    fmt::print(
        "{{\"ranks\": {}, \"backend\": \"{}\", \"device\": \"{}\", \"particles\": {}, "
        "\"bricks\": \"{}\", \"steps\": {}, \"ms_per_step\": {:.4f}, \"own_step_ms\": {:.4f}, "
        "\"halo_copy_ms\": {:.4f}, \"mpi_ms\": {:.4f}, \"partition_ms\": {:.4f}, "
        "\"partitions\": {}, \"halo_particles\": {}, \"halo\": \"{}\", \"setup_s\": {:.1f}}}\n",
        ranks, backend, sim.value()->device_info().name, sim.value()->particle_count(),
        sim.value()->decomposition().describe(), steps, seconds * per, most[0] * per, most[1] * per,
        most[2] * per, most[3] * per, after.partitions - before.partitions, halo_total,
        after.halo_direct ? "device" : "host", setup);
    if (!after.halo_direct && !after.halo_host_reason.empty()) {
      fmt::print(stderr, "mpi_bench: the halo goes through host memory: {}\n",
                 after.halo_host_reason);
    }
  }
  sim.value().reset();
  MPI_Finalize();
  return 0;
}
