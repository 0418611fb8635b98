// `motes resume CHECKPOINT`: goes on with a run from one of its checkpoints, appending to the same
// output series (docs/cli.md, docs/reliability.md).
#include <fmt/format.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "motes/checkpoint.h"
#include "motes/devices.h"
#include "motes/output.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "run_mpi.h"
#include "run_session.h"

namespace motes::cli {

namespace {

using Clock = std::chrono::steady_clock;

struct ResumeArgs {
  std::string checkpoint;
  std::string backend;  ///< empty: the checkpoint's
  int device = -1;
  int threads = 0;
  std::uint64_t steps = 0;
  double duration = 0.0;
  std::uint64_t checkpoint_every = 0;
  std::string halo;
  CLI::Option* steps_option = nullptr;
  CLI::Option* duration_option = nullptr;
  CLI::Option* checkpoint_every_option = nullptr;
};

/// Every check comes before anything is written: a refused resume leaves the series as it was.
void resume(const ResumeArgs& args) {
  const Clock::time_point start = Clock::now();
  const std::string& path = args.checkpoint;
  std::error_code ec;
  if (mpi_ranks() > 1 || std::filesystem::is_directory(path, ec)) {
    // A checkpoint set of a run over MPI ranks (or anything under mpirun -np N): run_mpi.h.
    DistributedResume d;
    d.halo_host = args.halo == "host";
    d.path = path;
    d.backend = args.backend;
    d.device = args.device;
    d.threads = args.threads;
    if (args.steps_option->count() > 0) d.steps = args.steps;
    if (args.duration_option->count() > 0) d.duration = args.duration;
    if (args.checkpoint_every_option->count() > 0) d.checkpoint_every = args.checkpoint_every;
    resume_distributed(d);
    return;
  }
  if (!args.halo.empty()) fail("--halo needs several MPI ranks: mpirun -np N motes resume SET");
  Result<CheckpointInfo> read = read_checkpoint_info(path);
  if (!read) fail(read.message());
  const CheckpointInfo& info = read.value();
  const CheckpointRun& run = info.run;
  if (!run.extension.empty()) fail(rank_file_refusal(path));
  if (info.version < 2) {
    fail(fmt::format(
        "{}: a version {} checkpoint (motes bench's, or an older motes's) holds no record of "
        "its run: motes resume needs version 2 or later (motes run --checkpoint-every)",
        path, info.version));
  }

  // The scene it came from, unchanged.
  Result<Scene> scene = Status::error("no scene");
  std::string scene_name;
  if (run.scene_file.empty()) {
    scene = builtin_default_scene();
    scene_name = "built-in default scene (examples/scenes/dominoes.json)";
  } else {
    Result<std::uint64_t> hash = scene_file_hash(run.scene_file);
    if (!hash) {
      fail(fmt::format("{}: cannot reload the run's scene: {}", path, hash.message()));
    }
    if (hash.value() != run.scene_hash) {
      fail(fmt::format(
          "{}: the scene file '{}' has changed since the checkpoint was written (FNV-1a {:016x} "
          "then, {:016x} now): it would not continue the same run",
          path, run.scene_file, run.scene_hash, hash.value()));
    }
    scene = load_scene_file(run.scene_file);
    scene_name = run.scene_path;
  }
  if (!scene) fail(scene.message());

  const std::string backend = args.backend.empty() ? info.backend : args.backend;
  DeviceOptions options;
  options.cpu_threads = args.threads;
  Result<std::unique_ptr<Device>> device = open_device(backend, args.device, options);
  if (!device) fail(device.message());
  Result<std::unique_ptr<Simulation>> sim =
      Simulation::create(scene.value(), std::move(device).value());
  if (!sim) fail(sim.message());
  if (Status s = sim.value()->load_state(path); !s) fail(s.message());

  SessionPlan plan;
  plan.sim = std::move(sim).value();
  plan.scene_name = scene_name;
  plan.resumed = true;
  plan.every = run.every > 0 ? run.every : 1;
  const std::uint64_t at = plan.sim->steps();
  if (args.steps_option->count() > 0) {
    plan.total = at + checked_steps(args.steps, "--steps");
  } else if (args.duration_option->count() > 0) {
    plan.total = at + steps_of_duration(args.duration, plan.sim->settings().dt);
  } else {
    plan.total = run.total_steps;
  }
  if (plan.total <= at) {
    fmt::print(
        "motes: {} is at step {}, the end of its run ({} steps): nothing to do (give --steps or "
        "--duration to go on)\n",
        path, at, run.total_steps);
    return;
  }
  plan.checkpoint_every =
      args.checkpoint_every_option->count() > 0 ? args.checkpoint_every : run.checkpoint_every;
  plan.record = run;
  plan.record.total_steps = plan.total;
  plan.record.checkpoint_every = plan.checkpoint_every;

  Result<OutputFormat> format = parse_output_format(run.output_format);
  if (!format) fail(fmt::format("{}: {}", path, format.message()));
  if (format.value() != OutputFormat::None) {
    std::vector<std::string> names;
    names.reserve(plan.sim->bodies().size());
    for (const BodyInfo& b : plan.sim->bodies()) names.push_back(b.name);
    Result<std::unique_ptr<FrameWriter>> writer =
        continue_frame_writer(format.value(), run.output_dir, std::move(names), run.series);
    if (!writer) fail(fmt::format("{}: {}", path, writer.message()));
    plan.writer = std::move(writer).value();
  }

  const DeviceInfo& dev = plan.sim->device().info();
  fmt::print("motes: resuming {} from {}: step {} of {} (t = {:.6g} s), written on {}\n",
             scene_name, path, at, plan.total, plan.sim->time(), info.backend);
  fmt::print("motes: device {} {}: {}{}\n", dev.backend, dev.index, dev.name,
             dev.detail.empty() ? "" : fmt::format(" ({})", dev.detail));
  fmt::print("motes: {} more steps; a frame every {} steps{}, after the {} already written\n",
             plan.total - at, plan.every,
             plan.writer ? fmt::format(" to {}", plan.writer->main_path()) : "",
             run.series.frame_times.size());
  if (dev.backend != info.backend) {
    fmt::print(
        "motes: note: the checkpoint was written on {}; on {} the run goes on within the "
        "backends' tolerances (docs/conformance.md), not bitwise as on {}\n",
        info.backend, dev.backend, info.backend);
  }
  std::fflush(stdout);
  plan.setup_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  run_session(std::move(plan));
}

}  // namespace

void add_resume_command(CLI::App& app) {
  auto args = std::make_shared<ResumeArgs>();
  CLI::App* sub = app.add_subcommand(
      "resume", "Go on with a run from a checkpoint (or set) of motes run --checkpoint-every");
  sub->add_option("CHECKPOINT", args->checkpoint,
                  "checkpoint file (checkpoint-<step>.mck), or under mpirun a checkpoint set "
                  "(checkpoint-<step>.mckset)")
      ->required();
  sub->add_option("--backend", args->backend,
                  "backend to go on with (default: the one that wrote the checkpoint)")
      ->check(CLI::IsMember({"auto", "openmp", "cuda", "vulkan"}));
  sub->add_option("--device", args->device, "device index within the backend (motes devices)")
      ->check(whole_number(0));
  sub->add_option(
         "--threads", args->threads,
         "OpenMP backend threads, kept whatever the load (default: OMP_NUM_THREADS or every core, "
         "fewer while other processes keep the CPUs busy)")
      ->check(whole_number(1));
  args->steps_option = sub->add_option("--steps", args->steps,
                                       "steps to run from the checkpoint (default: the rest of "
                                       "the original run)")
                           ->check(whole_number(0));
  args->duration_option =
      sub->add_option("--duration", args->duration, "simulated seconds to run from the checkpoint")
          ->check(finite_non_negative());
  args->steps_option->excludes(args->duration_option);
  args->checkpoint_every_option =
      sub->add_option("--checkpoint-every", args->checkpoint_every,
                      "a checkpoint every K steps (default: as the original run)")
          ->check(whole_number(1));
  add_halo_option(sub, args->halo);
  sub->callback([args] { resume(*args); });
}

}  // namespace motes::cli
