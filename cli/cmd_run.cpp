// `motes run [SCENE]`: runs a scene on a device, writes frames, reports progress and a summary.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <set>
#include <string>

#include "cli_util.h"
#include "commands.h"
#include "motes/checkpoint.h"
#include "motes/decomposition.h"
#include "motes/devices.h"
#include "motes/output.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "render_args.h"
#include "run_mpi.h"
#include "run_session.h"

namespace motes::cli {

namespace {

using Clock = std::chrono::steady_clock;

struct RunArgs {
  std::string scene;
  std::string backend = "auto";
  int device = -1;
  int threads = 0;
  std::uint64_t steps = 0;
  double duration = 0.0;
  std::string out = "out";
  std::uint64_t every = 0;
  std::string format = "vtu";
  std::string render_dir;
  std::uint64_t checkpoint_every = 0;
  std::string checkpoint_dir;
  std::string decomposition;
  std::string halo;
  RenderArgs render;
  CLI::Option* steps_option = nullptr;
  CLI::Option* duration_option = nullptr;
  CLI::Option* every_option = nullptr;
};

std::uint64_t total_steps(const RunArgs& a, const Settings& s) {
  if (a.steps_option->count() > 0) return checked_steps(a.steps, "--steps");
  return steps_of_duration(a.duration_option->count() > 0 ? a.duration : s.duration, s.dt);
}

std::uint64_t output_every(const RunArgs& a, const Settings& s) {
  if (a.every_option->count() > 0) return a.every;
  const double k = std::round(s.output_interval / s.dt);
  if (!(k >= 1.0)) return 1;
  return k > kMaxSteps ? static_cast<std::uint64_t>(kMaxSteps) : static_cast<std::uint64_t>(k);
}

/// The run after the arguments are parsed: loads the scene, opens the device and the outputs,
/// then hands over to run_session(). Exits through fail() on any error.
void run(const RunArgs& args) {
  const Clock::time_point start = Clock::now();
  Result<Scene> scene = args.scene.empty() ? builtin_default_scene() : load_scene_file(args.scene);
  mpi_agree_or_fail(scene ? Status::ok() : scene.status());
  // Mesh shapes filled by their winding number (open or non-manifold meshes) carry a warning;
  // bodies that share a mesh share it, so each is printed once.
  std::set<std::string> warned;
  for (const BodySpec& body : scene->bodies) {
    if (!body.shape || mpi_rank() != 0) continue;
    for (const std::string& warning : body.shape->warnings) {
      if (warned.insert(warning).second) fmt::print(stderr, "motes: warning: {}\n", warning);
    }
  }
  SessionPlan plan;
  plan.scene_name =
      args.scene.empty() ? "built-in default scene (examples/scenes/dominoes.json)" : args.scene;
  Result<OutputFormat> format = parse_output_format(args.format);
  if (!format) fail(format.message());

  plan.total = total_steps(args, scene->settings);
  plan.every = output_every(args, scene->settings);
  plan.checkpoint_every = args.checkpoint_every;

  // What each checkpoint records, so that `motes resume` can go on with the same series.
  CheckpointRun& record = plan.record;
  if (!args.scene.empty()) {
    record.scene_path = args.scene;
    record.scene_file = absolute_path(args.scene);
    Result<std::uint64_t> hash = scene_file_hash(args.scene);
    mpi_agree_or_fail(hash ? Status::ok() : hash.status());
    record.scene_hash = hash.value();
  }
  record.output_dir = absolute_path(args.out);
  record.output_format = output_format_name(format.value());
  record.every = plan.every;
  record.total_steps = plan.total;
  record.checkpoint_every = args.checkpoint_every;
  record.checkpoint_dir = absolute_path(
      args.checkpoint_dir.empty() ? (std::filesystem::path(args.out) / "checkpoints").string()
                                  : args.checkpoint_dir);

  if (mpi_ranks() > 1 || !args.decomposition.empty() || !args.halo.empty()) {
    // Over MPI ranks (docs/scale-out.md).
    if (mpi_ranks() == 1) {
      fail(fmt::format("{} needs several MPI ranks: mpirun -np N motes run",
                       args.decomposition.empty() ? "--halo" : "--decomposition"));
    }
    DistributedRun d;
    d.halo_host = args.halo == "host";
    if (!args.decomposition.empty()) {
      Result<std::array<int, 3>> cells = parse_decomposition(args.decomposition);
      if (!cells) fail(cells.message());
      d.decomposition = cells.value();
    }
    d.scene = std::move(scene).value();
    d.scene_name = plan.scene_name;
    d.backend = args.backend;
    d.device = args.device;
    d.threads = args.threads;
    d.total = plan.total;
    d.every = plan.every;
    d.format = format.value();
    d.out = args.out;
    d.checkpoint_every = args.checkpoint_every;
    d.record = record;
    d.render_dir = args.render_dir;
    d.render = args.render;
    d.setup_seconds = seconds_since(start);
    run_distributed(std::move(d));
    return;
  }

  DeviceOptions options;
  options.cpu_threads = args.threads;
  Result<std::unique_ptr<Device>> device = open_device(args.backend, args.device, options);
  if (!device) fail(device.message());
  Result<std::unique_ptr<Simulation>> sim =
      Simulation::create(scene.value(), std::move(device).value());
  if (!sim) fail(sim.message());
  plan.sim = std::move(sim).value();

  if (format.value() != OutputFormat::None) {
    std::vector<std::string> names;
    names.reserve(plan.sim->bodies().size());
    for (const BodyInfo& b : plan.sim->bodies()) names.push_back(b.name);
    Result<std::unique_ptr<FrameWriter>> writer =
        open_frame_writer(format.value(), args.out, std::move(names));
    if (!writer) fail(writer.message());
    plan.writer = std::move(writer).value();
  }

  const Settings& s = plan.sim->settings();
  const DeviceInfo& info = plan.sim->device().info();
  fmt::print("motes: {}: {} particles in {} bod{}\n", plan.scene_name, plan.sim->particle_count(),
             plan.sim->body_count(), plan.sim->body_count() == 1 ? "y" : "ies");
  fmt::print("motes: device {} {}: {}{}\n", info.backend, info.index, info.name,
             info.detail.empty() ? "" : fmt::format(" ({})", info.detail));
  fmt::print("motes: {} steps of {} s{} = {:.6g} s simulated; a frame every {} steps{}\n",
             plan.total, s.dt, s.substeps > 1 ? fmt::format(" ({} substeps)", s.substeps) : "",
             static_cast<double>(plan.total) * s.dt, plan.every,
             plan.writer ? fmt::format(" to {}", plan.writer->main_path())
                         : " (not written: --format none)");
  if (plan.checkpoint_every > 0) {
    fmt::print("motes: a checkpoint every {} steps in {} (the last two kept)\n",
               plan.checkpoint_every, record.checkpoint_dir);
  }
  std::fflush(stdout);
  if (!args.render_dir.empty()) {
    // Pictures of every frame: the scene's camera or one fitted to the initial particles.
    Result<Snapshot> first = plan.sim->snapshot();
    if (!first) fail(first.message());
    // An emitter's particles wait out of sight: the camera frames its nozzle instead.
    render::RenderSettings settings =
        render_settings(args.render, render::look_from_scene(scene.value()), scene->camera,
                        camera_points(*plan.sim, scene.value(), std::move(first.value())));
    const double interval = static_cast<double>(plan.every) * s.dt;
    plan.render = open_render_output(args.render, std::move(settings), args.render_dir, interval,
                                     scene->camera.has_value());
  }
  plan.setup_seconds = seconds_since(start);
  run_session(std::move(plan));
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* sub = app.add_subcommand("run", "Run a scene and write frames");
  sub->add_option("SCENE", args->scene,
                  "scene file (JSON, docs/scene-format.md); default: the built-in domino chain");
  sub->add_option("--backend", args->backend, "backend to run on (auto: the first with a device)")
      ->check(CLI::IsMember({"auto", "openmp", "cuda", "vulkan"}))
      ->capture_default_str();
  sub->add_option("--device", args->device, "device index within the backend (motes devices)")
      ->check(whole_number_of<int>(0));
  args->steps_option =
      sub->add_option("--steps", args->steps, "number of steps to run")->check(whole_number(0));
  args->duration_option =
      sub->add_option("--duration", args->duration,
                      "simulated seconds to run (default: the scene's settings.duration)")
          ->check(finite_non_negative());
  args->steps_option->excludes(args->duration_option);
  sub->add_option("--out", args->out, "output directory")->capture_default_str();
  args->every_option =
      sub->add_option("--every", args->every,
                      "write a frame every K steps (default: settings.output_interval / dt)")
          ->check(whole_number(1));
  sub->add_option("--format", args->format, "output files: vtu (+ .pvd), csv or none")
      ->check(CLI::IsMember({"vtu", "csv", "none"}))
      ->capture_default_str();
  sub->add_option(
         "--threads", args->threads,
         "OpenMP backend threads, kept whatever the load (default: OMP_NUM_THREADS or every core, "
         "fewer while other processes keep the CPUs busy)")
      ->check(whole_number_of<int>(1, kMaxThreads));
  sub->add_option("--render", args->render_dir,
                  "also draw every frame as a PNG in this directory, and an MP4 when ffmpeg is "
                  "installed (docs/rendering.md)");
  add_render_options(sub, args->render);
  sub->add_option("--checkpoint-every", args->checkpoint_every,
                  "write a checkpoint every K steps (the last two kept; motes resume goes on "
                  "from one)")
      ->check(whole_number(1));
  sub->add_option("--decomposition", args->decomposition,
                  "under mpirun: bricks along x, y, z as X,Y,Z (their product = the rank count; "
                  "default: the least cut area; docs/scale-out.md)");
  add_halo_option(sub, args->halo);
  sub->add_option("--checkpoint-dir", args->checkpoint_dir,
                  "directory of the checkpoints (default: OUT/checkpoints)");
  sub->callback([args] { run(*args); });
}

}  // namespace motes::cli
