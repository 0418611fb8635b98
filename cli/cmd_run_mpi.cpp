// `motes run` and `motes resume` over MPI ranks (run_mpi.h, docs/scale-out.md): MPI's start and
// end, and the setup of a run or a resume; run_mpi_session.cpp steps it.
#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli_util.h"
#include "motes/checkpoint.h"
#include "motes/devices.h"
#include "motes/render.h"
#include "motes/scene.h"
#include "render_args.h"
#include "run_mpi.h"

#ifdef MOTES_HAVE_MPI
#include <mpi.h>

#include "motes/distributed.h"
#include "run_mpi_session.h"
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

/// The device this rank opens: --device, or the rank's index on its host among the backend's
/// devices (one GPU per rank); the CPU backend has one device.
DeviceOpener device_opener(std::string backend, int index, int threads) {
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
  options.cpu_threads = threads;
  return [backend, index, options]() { return open_device(backend, index, options); };
}

/// Collective: every rank's device, as "rank R: device ..." lines (rank 0; empty elsewhere).
std::string device_lines(const DistributedSimulation& sim) {
  const int rank = mpi_rank();
  const int ranks = mpi_ranks();
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
  std::string lines;
  for (int r = 0; rank == 0 && r < ranks; ++r) {
    lines +=
        fmt::format("motes: rank {}: device {}\n", r,
                    all.substr(static_cast<std::size_t>(at[static_cast<std::size_t>(r)]),
                               static_cast<std::size_t>(lengths[static_cast<std::size_t>(r)])));
  }
  return lines;
}

/// The frame writer's names: the scene's bodies.
std::vector<std::string> body_names(const DistributedSimulation& sim) {
  std::vector<std::string> names;
  names.reserve(sim.bodies().size());
  for (const BodyInfo& b : sim.bodies()) names.push_back(b.name);
  return names;
}

template <typename T>
Status status_of(const Result<T>& r) {
  return r ? Status::ok() : r.status();
}

}  // namespace

void run_distributed(DistributedRun run) {
  const Clock::time_point start = Clock::now();
  const int ranks = mpi_ranks();
  DistributedOptions options;
  options.decomposition = run.decomposition;
  options.halo = run.halo_host ? DistributedOptions::Halo::Host : DistributedOptions::Halo::Auto;
  Result<std::unique_ptr<DistributedSimulation>> created = DistributedSimulation::create(
      run.scene, MPI_COMM_WORLD, device_opener(run.backend, run.device, run.threads), options);
  if (!created) fail(created.message());  // the same message on every rank, printed by rank 0
  DistributedPlan plan;
  plan.sim = std::move(created).value();
  DistributedSimulation& sim = *plan.sim;
  plan.scene_name = run.scene_name;
  plan.total = run.total;
  plan.every = run.every;
  plan.checkpoint_every = run.checkpoint_every;
  plan.record = run.record;
  on_rank0([&] {
    if (run.format == OutputFormat::None) return;
    Result<std::unique_ptr<FrameWriter>> w =
        open_frame_writer(run.format, run.out, body_names(sim));
    if (!w) fail(w.message());
    plan.writer = std::move(w).value();
  });

  const std::string devices = device_lines(sim);
  const Settings& s = sim.settings();
  on_rank0([&] {
    fmt::print("motes: {}: {} particles in {} bod{} over {} MPI ranks (bricks {})\n",
               run.scene_name, sim.particle_count(), sim.bodies().size(),
               sim.bodies().size() == 1 ? "y" : "ies", ranks, sim.decomposition().describe());
    fmt::print("{}", devices);
    fmt::print("motes: {} steps of {} s = {:.6g} s simulated; a frame every {} steps{}\n",
               run.total, s.dt, static_cast<double>(run.total) * s.dt, run.every,
               plan.writer ? fmt::format(" to {}", plan.writer->main_path())
                           : " (not written: --format none)");
    if (run.checkpoint_every > 0) {
      fmt::print("motes: a checkpoint set every {} steps in {} (the last two kept)\n",
                 run.checkpoint_every, run.record.checkpoint_dir);
    }
    std::fflush(stdout);
  });
  if (!run.render_dir.empty()) {
    // Pictures of every frame, drawn by rank 0 from the gathered state as one process draws them:
    // the scene's camera or one fitted to the initial particles.
    Result<Snapshot> first = sim.gather(0);
    if (!first) fail(first.message());
    on_rank0([&] {
      render::RenderSettings settings = render_settings(
          run.render, render::look_from_scene(run.scene), run.scene.camera, first->particle_pos);
      const double interval = static_cast<double>(run.every) * s.dt;
      plan.render = open_render_output(run.render, std::move(settings), run.render_dir, interval,
                                       run.scene.camera.has_value());
    });
  }
  plan.setup_seconds = run.setup_seconds + seconds_since(start);
  run_distributed_session(std::move(plan));
}

void resume_distributed(const DistributedResume& args) {
  const Clock::time_point start = Clock::now();
  const std::string& path = args.path;
  const int ranks = mpi_ranks();
  std::error_code ec;
  if (!std::filesystem::is_directory(path, ec)) {
    // A file: a single process's checkpoint, or one rank's file of a set.
    Result<CheckpointInfo> file = read_checkpoint_info(path);
    mpi_agree_or_fail(status_of(file));
    if (!file->run.extension.empty()) fail(rank_file_refusal(path));
    fail(fmt::format(
        "{}: a checkpoint of one process; this run has {} MPI ranks: resume it in one process "
        "(motes resume {}, without mpirun)",
        path, ranks, path));
  }
  Result<CheckpointSetInfo> read = read_checkpoint_set(path);
  mpi_agree_or_fail(status_of(read));
  const CheckpointSetInfo& info = read.value();
  if (info.ranks != ranks || !mpi_started) {
    fail(fmt::format(
        "{}: a checkpoint set of {} MPI rank{}; this run has {}: resume it with mpirun -np {} "
        "motes resume {}",
        path, info.ranks, info.ranks == 1 ? "" : "s", ranks, info.ranks, path));
  }
  const CheckpointRun& run = info.run;

  // The scene it came from, unchanged.
  Result<Scene> scene = Status::error("no scene");
  std::string scene_name;
  if (run.scene_file.empty()) {
    scene = builtin_default_scene();
    scene_name = "built-in default scene (examples/scenes/dominoes.json)";
  } else {
    Result<std::uint64_t> hash = scene_file_hash(run.scene_file);
    mpi_agree_or_fail(hash ? Status::ok()
                           : Status::error(fmt::format("{}: cannot reload the run's scene: {}",
                                                       path, hash.message())));
    if (hash.value() != run.scene_hash) {
      fail(fmt::format(
          "{}: the scene file '{}' has changed since the checkpoint set was written (FNV-1a "
          "{:016x} then, {:016x} now): it would not continue the same run",
          path, run.scene_file, run.scene_hash, hash.value()));
    }
    scene = load_scene_file(run.scene_file);
    scene_name = run.scene_path;
  }
  mpi_agree_or_fail(status_of(scene));

  const std::string backend = args.backend.empty() ? info.backend : args.backend;
  Result<std::unique_ptr<DistributedSimulation>> resumed = DistributedSimulation::resume(
      scene.value(), MPI_COMM_WORLD, device_opener(backend, args.device, args.threads), path,
      args.halo_host ? DistributedOptions::Halo::Host : DistributedOptions::Halo::Auto);
  if (!resumed) fail(resumed.message());
  DistributedPlan plan;
  plan.sim = std::move(resumed).value();
  DistributedSimulation& sim = *plan.sim;
  plan.scene_name = scene_name;
  plan.resumed = true;
  plan.every = run.every > 0 ? run.every : 1;
  const std::uint64_t at = sim.steps();
  if (args.steps) {
    plan.total = at + checked_steps(*args.steps, "--steps");
  } else if (args.duration) {
    plan.total = at + steps_of_duration(*args.duration, sim.settings().dt);
  } else {
    plan.total = run.total_steps;
  }
  if (plan.total <= at) {
    on_rank0([&] {
      fmt::print(
          "motes: {} is at step {}, the end of its run ({} steps): nothing to do (give --steps "
          "or --duration to go on)\n",
          path, at, run.total_steps);
    });
    return;
  }
  plan.checkpoint_every = args.checkpoint_every ? *args.checkpoint_every : run.checkpoint_every;
  plan.record = run;
  plan.record.total_steps = plan.total;
  plan.record.checkpoint_every = plan.checkpoint_every;

  Result<OutputFormat> format = parse_output_format(run.output_format);
  if (!format) fail(fmt::format("{}: {}", path, format.message()));
  // Every check is done: only now is the series continued (a CSV cut to its size at the set).
  on_rank0([&] {
    if (format.value() == OutputFormat::None) return;
    Result<std::unique_ptr<FrameWriter>> writer =
        continue_frame_writer(format.value(), run.output_dir, body_names(sim), run.series);
    if (!writer) fail(fmt::format("{}: {}", path, writer.message()));
    plan.writer = std::move(writer).value();
  });

  const std::string devices = device_lines(sim);
  const std::string now = sim.device_info().backend;
  on_rank0([&] {
    fmt::print(
        "motes: resuming {} from {}: step {} of {} (t = {:.6g} s) over {} MPI ranks (bricks {}), "
        "written on {}\n",
        scene_name, path, at, plan.total, sim.time(), ranks, sim.decomposition().describe(),
        info.backend);
    fmt::print("{}", devices);
    fmt::print("motes: {} more steps; a frame every {} steps{}, after the {} already written\n",
               plan.total - at, plan.every,
               plan.writer ? fmt::format(" to {}", plan.writer->main_path()) : "",
               run.series.frame_times.size());
    if (!now.empty() && now != info.backend) {
      fmt::print(
          "motes: note: the set was written on {}; on {} the run goes on within the backends' "
          "tolerances (docs/conformance.md), not bitwise as on {}\n",
          info.backend, now, info.backend);
    }
    std::fflush(stdout);
  });
  plan.setup_seconds = seconds_since(start);
  run_distributed_session(std::move(plan));
}

std::string rank_file_refusal(const std::string& path) {
  const std::string set = std::filesystem::path(path).parent_path().string();
  Result<CheckpointSetInfo> info = read_checkpoint_set(set.empty() ? "." : set);
  if (!info) {
    return fmt::format(
        "{}: one rank's file of a checkpoint set over MPI ranks, whose set cannot be read ({}): a "
        "set is resumed whole, with mpirun -np N motes resume SET",
        path, info.message());
  }
  return fmt::format(
      "{}: one rank's file of the checkpoint set {} of {} MPI ranks: resume the whole set with "
      "mpirun -np {} motes resume {}",
      path, set, info->ranks, info->ranks, set);
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

void resume_distributed(const DistributedResume& resume) {
  fail(
      fmt::format("{}: a checkpoint set of a run over MPI ranks: this motes was built without MPI "
                  "(docs/scale-out.md)",
                  resume.path));
}

std::string rank_file_refusal(const std::string& path) {
  return fmt::format(
      "{}: one rank's file of a checkpoint set over MPI ranks: resume the whole set with mpirun "
      "(this motes was built without MPI; docs/scale-out.md)",
      path);
}

#endif

}  // namespace motes::cli
