// `motes run` over MPI ranks (run_mpi.h, docs/scale-out.md).
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "cli_util.h"
#include "motes/devices.h"
#include "progress.h"
#include "run_mpi.h"

#ifdef MOTES_HAVE_MPI
#include <mpi.h>

#include "motes/distributed.h"
#endif

namespace motes::cli {

namespace {

/// The rank count the launcher announced (OpenMPI, MPICH/Hydra or Slurm's PMI, PMIx), 0 when
/// this process was not launched as a rank.
int launched_ranks() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"}) {
    if (const char* v = std::getenv(name); v != nullptr && *v != '\0') return std::atoi(v);
  }
  return std::getenv("PMIX_RANK") != nullptr ? 1 : 0;
}

}  // namespace

#ifdef MOTES_HAVE_MPI

namespace {

/// The rank's index among the ranks on its host, for the default device.
int local_rank() {
  for (const char* name : {"OMPI_COMM_WORLD_LOCAL_RANK", "MPI_LOCALRANKID", "SLURM_LOCALID"}) {
    if (const char* v = std::getenv(name); v != nullptr && *v != '\0') return std::atoi(v);
  }
  return 0;
}

bool mpi_started = false;

}  // namespace

MpiSession::MpiSession(int& argc, char**& argv) {
  if (launched_ranks() == 0) return;
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  mpi_started = true;
}

MpiSession::~MpiSession() {
  if (mpi_started) MPI_Finalize();
}

int mpi_ranks() {
  int size = 1;
  if (mpi_started) MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

int mpi_rank() {
  int rank = 0;
  if (mpi_started) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

void mpi_agree_or_fail(const Status& mine) {
  if (Status s = mpi_ranks() > 1 ? agree(MPI_COMM_WORLD, mine) : mine; !s) fail(s.message());
}

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The device this rank opens: --device, or the rank's index on its host among the backend's
/// devices (one GPU per rank); the CPU backend has one device.
DeviceOpener device_opener(const DistributedRun& run) {
  std::string backend = run.backend;
  int index = run.device;
  if (backend == "auto") {
    Result<std::unique_ptr<Device>> probe = open_device("auto");
    if (probe) backend = probe.value()->info().backend;
  }
  if (index < 0 && backend != "openmp" && backend != "auto") {
    for (const BackendReport& r : list_backends()) {
      if (r.backend == backend && !r.devices.empty()) {
        index = local_rank() % static_cast<int>(r.devices.size());
      }
    }
  }
  DeviceOptions options;
  options.cpu_threads = run.threads;
  return [backend, index, options]() { return open_device(backend, index, options); };
}

/// The motion guard of a run over ranks, on the state rank 0 gathered (docs/scale-out.md): a
/// non-finite particle is an error naming step, body and particle (scene indices); the fastest
/// particle's travel per substep beyond Simulation::kSafeTravel of its diameter is a warning.
Status guard(const Snapshot& s, const DistributedSimulation& sim, double& travel,
             std::string& warning) {
  const Settings& settings = sim.settings();
  const double h = settings.dt / static_cast<double>(settings.substeps);
  travel = 0.0;
  std::size_t fastest = 0;
  for (std::size_t i = 0; i < s.particle_pos.size(); ++i) {
    const shared::vec4& p = s.particle_pos[i];
    const shared::vec4& v = s.particle_vel[i];
    const std::uint32_t b = s.particle_body[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(v.x) ||
        !std::isfinite(v.y) || !std::isfinite(v.z)) {
      return Status::error(fmt::format(
          "non-finite state at step {} (t = {:.6g} s): particle {} of body {} '{}': position "
          "({}, {}, {}) m, velocity ({}, {}, {}) m/s; the run has gone unstable (dt {:.4g} s at "
          "substeps {} too large for the contact stiffness?)",
          s.step, s.time, i, b, sim.bodies()[b].name, p.x, p.y, p.z, v.x, v.y, v.z, settings.dt,
          settings.substeps));
    }
    const double speed = std::sqrt(static_cast<double>(v.x) * static_cast<double>(v.x) +
                                   static_cast<double>(v.y) * static_cast<double>(v.y) +
                                   static_cast<double>(v.z) * static_cast<double>(v.z));
    const double t = p.w > 0.0f ? speed * h / (2.0 * static_cast<double>(p.w)) : 0.0;
    if (t > travel) {
      travel = t;
      fastest = i;
    }
  }
  warning.clear();
  if (travel > Simulation::kSafeTravel) {
    const shared::vec4& p = s.particle_pos[fastest];
    const std::uint32_t b = s.particle_body[fastest];
    const double diameter = 2.0 * static_cast<double>(p.w);
    const double speed = travel * diameter / h;
    warning = fmt::format(
        "step {} (t = {:.6g} s): particle {} of body {} '{}' moves {:.3g} of its diameter "
        "({:.4g} m) per substep at {:.4g} m/s, more than the {} that contacts are resolved at: "
        "contacts can be missed (tunnelling); the largest safe dt at this speed is {:.4g} s at "
        "substeps {} (dt is {:.4g} s)",
        s.step, s.time, fastest, b, sim.bodies()[b].name, travel, diameter, speed,
        Simulation::kSafeTravel,
        Simulation::kSafeTravel * diameter / speed * static_cast<double>(settings.substeps),
        settings.substeps, settings.dt);
  }
  return Status::ok();
}

}  // namespace

void run_distributed(DistributedRun run) {
  const Clock::time_point start = Clock::now();
  const int rank = mpi_rank();
  const int ranks = mpi_ranks();
  DistributedOptions options;
  options.decomposition = run.decomposition;
  Result<std::unique_ptr<DistributedSimulation>> created =
      DistributedSimulation::create(run.scene, MPI_COMM_WORLD, device_opener(run), options);
  if (!created) fail(created.message());  // the same message on every rank, printed by rank 0
  DistributedSimulation& sim = *created.value();

  std::unique_ptr<FrameWriter> writer;
  Status opened = Status::ok();
  if (rank == 0 && run.format != OutputFormat::None) {
    std::vector<std::string> names;
    for (const BodyInfo& b : sim.bodies()) names.push_back(b.name);
    Result<std::unique_ptr<FrameWriter>> w = open_frame_writer(run.format, run.out, names);
    if (w) {
      writer = std::move(w).value();
    } else {
      opened = w.status();
    }
  }
  mpi_agree_or_fail(opened);

  // Every rank's device, for the header.
  const DeviceInfo& info = sim.device_info();
  const std::string mine = fmt::format("{} {}: {}", info.backend, info.index, info.name);
  int length = static_cast<int>(mine.size());
  std::vector<int> lengths(static_cast<std::size_t>(ranks)), at(static_cast<std::size_t>(ranks));
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::string all;
  if (rank == 0) {
    int total = 0;
    for (int r = 0; r < ranks; ++r) {
      at[static_cast<std::size_t>(r)] = total;
      total += lengths[static_cast<std::size_t>(r)];
    }
    all.resize(static_cast<std::size_t>(total));
  }
  MPI_Gatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), at.data(), MPI_CHAR, 0,
              MPI_COMM_WORLD);
  const Settings& s = sim.settings();
  if (rank == 0) {
    fmt::print("motes: {}: {} particles in {} bod{} over {} MPI ranks (bricks {})\n",
               run.scene_name, sim.particle_count(), sim.bodies().size(),
               sim.bodies().size() == 1 ? "y" : "ies", ranks, sim.decomposition().describe());
    for (int r = 0; r < ranks; ++r) {
      fmt::print("motes: rank {}: device {}\n", r,
                 all.substr(static_cast<std::size_t>(at[static_cast<std::size_t>(r)]),
                            static_cast<std::size_t>(lengths[static_cast<std::size_t>(r)])));
    }
    fmt::print(
        "motes: {} steps of {} s = {:.6g} s simulated; a frame every {} steps{}\n", run.total, s.dt,
        static_cast<double>(run.total) * s.dt, run.every,
        writer ? fmt::format(" to {}", writer->main_path()) : " (not written: --format none)");
    std::fflush(stdout);
  }

  double step_seconds = 0.0;
  double output_seconds = 0.0;
  // At every frame and at least every Simulation::kGuardInterval steps: the state gathered on
  // rank 0, checked by the guard, and at frames written.
  std::uint64_t checks = 0;
  std::uint64_t warned = 0;
  double worst = 0.0;
  double last_warned = 0.0;
  const auto check = [&](bool write) {
    const Clock::time_point t = Clock::now();
    Result<Snapshot> snap = sim.gather(0);
    Status ok = snap ? Status::ok() : snap.status();
    if (ok && rank == 0) {
      double travel = 0.0;
      std::string warning;
      ok = guard(snap.value(), sim, travel, warning);
      ++checks;
      if (!warning.empty()) {
        ++warned;
        worst = std::max(worst, travel);
        if (travel > 2.0 * last_warned) {
          fmt::print(stderr, "motes: warning: {}\n", warning);
          last_warned = travel;
        }
      }
      if (ok && write && writer) ok = writer->write_frame(snap.value());
      if (!ok && writer) (void)writer->finish();  // the frames so far stay readable
    }
    mpi_agree_or_fail(ok);
    output_seconds += seconds_since(t);
  };
  const auto frame = [&]() { check(true); };
  std::unique_ptr<Progress> progress;
  if (rank == 0) progress = std::make_unique<Progress>(run.total);
  const double setup = run.setup_seconds + seconds_since(start);
  const Clock::time_point loop = Clock::now();
  frame();
  while (sim.steps() < run.total) {
    const std::uint64_t next_frame = (sim.steps() / run.every + 1) * run.every;
    const std::uint64_t next =
        std::min({run.total, next_frame, sim.steps() + Simulation::kGuardInterval});
    const Clock::time_point t = Clock::now();
    if (Status st = sim.step(next - sim.steps()); !st) {
      if (progress) progress->finish();
      if (writer) (void)writer->finish();
      fail(st.message());
    }
    step_seconds += seconds_since(t);
    check(sim.steps() == next_frame || sim.steps() == run.total);
    if (progress) progress->update(sim.steps(), sim.time());
  }
  if (progress) progress->finish();
  Status finished = writer ? writer->finish() : Status::ok();
  mpi_agree_or_fail(finished);

  // Totals over the ranks for the summary.
  const DistributedStats st = sim.stats();
  const std::uint64_t mine_counts[3] = {st.halo_bodies, st.halo_particles, st.halo_bytes};
  std::uint64_t sums[3] = {0, 0, 0};
  MPI_Reduce(mine_counts, sums, 3, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
  // The busiest rank's seconds in each part.
  const double mine_seconds[4] = {st.copy_seconds, st.mpi_seconds, st.partition_seconds,
                                  st.step_seconds};
  double most[4] = {0.0, 0.0, 0.0, 0.0};
  MPI_Reduce(mine_seconds, most, 4, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  const double wall = seconds_since(loop);
  if (rank != 0) return;
  const double rate = step_seconds > 0.0 ? static_cast<double>(sim.steps()) / step_seconds : 0.0;
  fmt::print("motes: done\n");
  fmt::print("  {:<16}{} ranks, bricks {}\n", "ranks", ranks, sim.decomposition().describe());
  fmt::print("  {:<16}{}\n", "particles", sim.particle_count());
  fmt::print("  {:<16}{}\n", "bodies", sim.bodies().size());
  fmt::print("  {:<16}{} of {}\n", "steps", sim.steps(), run.total);
  fmt::print("  {:<16}{:.6g} s\n", "simulated time", sim.time());
  fmt::print(
      "  {:<16}{} partitions, {} bodies migrated; at the end {} halo copies ({} particles)\n",
      "decomposition", st.partitions, st.migrations, sums[0], sums[1]);
  fmt::print("  {:<16}the slowest rank's own steps {}\n", "ranks' steps", format_seconds(most[3]));
  fmt::print(
      "  {:<16}{}B sent; a rank's most: {} copying state, {} in MPI (transfer and waiting "
      "for the slowest rank), {} partitioning\n",
      "halos", format_si(static_cast<double>(sums[2])), format_seconds(most[0]),
      format_seconds(most[1]), format_seconds(most[2]));
  fmt::print("  {:<16}{} (scene, devices and first partition)\n", "setup", format_seconds(setup));
  fmt::print("  {:<16}{} (stepping {}, gathering and output {})\n", "wall time",
             format_seconds(wall), format_seconds(step_seconds), format_seconds(output_seconds));
  fmt::print("  {:<16}{} steps/s, {} particle-steps/s (stepping, halos included)\n", "speed",
             format_si(rate), format_si(rate * static_cast<double>(sim.particle_count())));
  if (writer) {
    fmt::print("  {:<16}{} written to {}\n", "frames", writer->frames(), writer->main_path());
  } else {
    fmt::print("  {:<16}none written (--format none)\n", "frames");
  }
  fmt::print("  {:<16}{} motion check{} on the gathered state{}\n", "guards", checks,
             checks == 1 ? "" : "s",
             warned == 0 ? std::string(", no warning")
                         : fmt::format(", {} with a tunnelling warning (the worst: {:.3g} of a "
                                       "diameter per substep)",
                                       warned, worst));
  std::fflush(stdout);
}

#else  // built without MPI

MpiSession::MpiSession(int& /*argc*/, char**& /*argv*/) {
  if (launched_ranks() > 1) {
    fmt::print(stderr,
               "motes: error: launched as one of {} MPI ranks, but this motes was built without "
               "MPI (Debian: apt-get install libopenmpi-dev openmpi-bin, then build again; "
               "docs/scale-out.md)\n",
               launched_ranks());
    std::exit(kErrorExit);
  }
}

MpiSession::~MpiSession() = default;

int mpi_ranks() { return 1; }
int mpi_rank() { return 0; }

void mpi_agree_or_fail(const Status& mine) {
  if (!mine) fail(mine.message());
}

void run_distributed(DistributedRun /*run*/) {
  fail("this motes was built without MPI (docs/scale-out.md)");
}

#endif

}  // namespace motes::cli
