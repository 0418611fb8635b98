// `motes run [SCENE]`: runs a scene on a device, writes frames, reports progress and a summary.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <memory>
#include <set>
#include <string>

#include "cli_util.h"
#include "commands.h"
#include "motes/devices.h"
#include "motes/output.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "progress.h"
#include "render_args.h"

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
  RenderArgs render;
  CLI::Option* steps_option = nullptr;
  CLI::Option* duration_option = nullptr;
  CLI::Option* every_option = nullptr;
};

// More steps than this in one run is a mistake in the arguments or the scene (dt too small).
constexpr double kMaxSteps = 1e13;
// Steps go to the device in chunks sized to take about this long, so that progress, Ctrl-C
// and device errors are seen promptly without a call per step.
constexpr double kChunkSeconds = 0.1;
constexpr std::uint64_t kMaxChunk = std::uint64_t{1} << 20;

volatile std::sig_atomic_t g_interrupted = 0;

extern "C" void on_interrupt(int /*signal*/) {
  g_interrupted = 1;
  // A second Ctrl-C ends the process at once.
  std::signal(SIGINT, SIG_DFL);
}

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::uint64_t total_steps(const RunArgs& a, const Settings& s) {
  if (a.steps_option->count() > 0) {
    if (static_cast<double>(a.steps) > kMaxSteps) {
      fail(fmt::format("--steps {} is more than {:.0e} steps", a.steps, kMaxSteps));
    }
    return a.steps;
  }
  const double duration = a.duration_option->count() > 0 ? a.duration : s.duration;
  const double n = std::round(duration / s.dt);
  if (!(n <= kMaxSteps)) {
    fail(fmt::format("a duration of {} s at dt = {} s is {:.3g} steps: too many", duration, s.dt,
                     n));
  }
  return static_cast<std::uint64_t>(n);
}

std::uint64_t output_every(const RunArgs& a, const Settings& s) {
  if (a.every_option->count() > 0) return a.every;
  const double k = std::round(s.output_interval / s.dt);
  if (!(k >= 1.0)) return 1;
  return k > kMaxSteps ? static_cast<std::uint64_t>(kMaxSteps) : static_cast<std::uint64_t>(k);
}

/// The whole run, after the arguments are parsed: exits through fail() on any error.
class Runner {
 public:
  explicit Runner(const RunArgs& args) : args_(args) {}

  void run() {
    const Clock::time_point start = Clock::now();
    setup();
    setup_seconds_ = seconds_since(start);
    loop();
    summary();
    if (interrupted_) throw CLI::RuntimeError(130);  // as a shell reports SIGINT
  }

 private:
  void setup() {
    Result<Scene> scene =
        args_.scene.empty() ? builtin_default_scene() : load_scene_file(args_.scene);
    if (!scene) fail(scene.message());
    // Mesh shapes filled by their winding number (open or non-manifold meshes) carry a warning;
    // bodies that share a mesh share it, so each is printed once.
    std::set<std::string> warned;
    for (const BodySpec& body : scene->bodies) {
      if (!body.shape) continue;
      for (const std::string& warning : body.shape->warnings) {
        if (warned.insert(warning).second) fmt::print(stderr, "motes: warning: {}\n", warning);
      }
    }
    scene_name_ = args_.scene.empty() ? "built-in default scene (examples/scenes/dominoes.json)"
                                      : args_.scene;
    Result<OutputFormat> format = parse_output_format(args_.format);
    if (!format) fail(format.message());

    total_ = total_steps(args_, scene->settings);
    every_ = output_every(args_, scene->settings);

    DeviceOptions options;
    options.cpu_threads = args_.threads;
    Result<std::unique_ptr<Device>> device = open_device(args_.backend, args_.device, options);
    if (!device) fail(device.message());
    Result<std::unique_ptr<Simulation>> sim =
        Simulation::create(scene.value(), std::move(device).value());
    if (!sim) fail(sim.message());
    sim_ = std::move(sim).value();

    if (format.value() != OutputFormat::None) {
      std::vector<std::string> names;
      names.reserve(sim_->bodies().size());
      for (const BodyInfo& b : sim_->bodies()) names.push_back(b.name);
      Result<std::unique_ptr<FrameWriter>> writer =
          open_frame_writer(format.value(), args_.out, std::move(names));
      if (!writer) fail(writer.message());
      writer_ = std::move(writer).value();
    }

    const Settings& s = sim_->settings();
    const DeviceInfo& info = sim_->device().info();
    fmt::print("motes: {}: {} particles in {} bod{}\n", scene_name_, sim_->particle_count(),
               sim_->body_count(), sim_->body_count() == 1 ? "y" : "ies");
    fmt::print("motes: device {} {}: {}{}\n", info.backend, info.index, info.name,
               info.detail.empty() ? "" : fmt::format(" ({})", info.detail));
    fmt::print(
        "motes: {} steps of {} s{} = {:.6g} s simulated; a frame every {} steps{}\n", total_, s.dt,
        s.substeps > 1 ? fmt::format(" ({} substeps)", s.substeps) : "",
        static_cast<double>(total_) * s.dt, every_,
        writer_ ? fmt::format(" to {}", writer_->main_path()) : " (not written: --format none)");
    std::fflush(stdout);
    if (!args_.render_dir.empty()) setup_render(scene.value());
  }

  /// Pictures of every frame: the scene's camera or one fitted to the initial particles.
  void setup_render(const Scene& scene) {
    Result<Snapshot> first = sim_->snapshot();
    if (!first) fail(first.message());
    render::RenderSettings settings = render_settings(args_.render, render::look_from_scene(scene),
                                                      scene.camera, first->particle_pos);
    const double interval = static_cast<double>(every_) * sim_->settings().dt;
    render_ = open_render_output(args_.render, std::move(settings), args_.render_dir, interval,
                                 scene.camera.has_value());
  }

  /// Checks the state and writes it as the next frame.
  void output_frame() {
    const Clock::time_point start = Clock::now();
    if (Status s = sim_->check_finite(); !s) fail(s.message());
    if (writer_ || render_) {
      Result<Snapshot> snapshot = sim_->snapshot();
      if (!snapshot) fail(snapshot.message());
      if (writer_) {
        if (Status s = writer_->write_frame(snapshot.value()); !s) fail(s.message());
      }
      if (render_) {
        if (Status s = render_->add_frame(snapshot.value()); !s) fail(s.message());
      }
    }
    last_output_step_ = sim_->steps();
    output_seconds_ += seconds_since(start);
  }

  void loop() {
    g_interrupted = 0;
    const auto previous = std::signal(SIGINT, on_interrupt);
    const Clock::time_point start = Clock::now();
    Progress progress(total_);

    try {
      run_steps(progress);
    } catch (const CLI::RuntimeError&) {
      progress.finish();  // so that the error starts on a line of its own
      throw;
    }
    progress.finish();
    std::signal(SIGINT, previous);
    wall_seconds_ = seconds_since(start);
    if (writer_) {
      if (Status s = writer_->finish(); !s) fail(s.message());
    }
    if (render_) {
      if (Status s = render_->finish(); !s) fail(s.message());
    }
  }

  /// Frame 0, the steps with a frame every every_ steps, and the final state.
  void run_steps(Progress& progress) {
    output_frame();
    std::uint64_t done = 0;
    std::uint64_t next_frame = every_;
    std::uint64_t chunk = 1;
    while (done < total_) {
      if (g_interrupted != 0) {
        interrupted_ = true;
        break;
      }
      const std::uint64_t n = std::min({chunk, total_ - done, next_frame - done});
      const Clock::time_point t0 = Clock::now();
      if (Status s = sim_->step(n); !s) fail(s.message());
      if (Status s = sim_->device().synchronize(); !s) fail(s.message());
      const double took = seconds_since(t0);
      step_seconds_ += took;
      done += n;
      if (took < kChunkSeconds / 2 && chunk < kMaxChunk) chunk *= 2;
      if (took > kChunkSeconds * 2 && chunk > 1) chunk /= 2;
      if (done == next_frame) {
        output_frame();
        next_frame += every_;
      }
      progress.update(done, sim_->time());
    }
    // The final state is always a frame, also when the step count is not a multiple of --every.
    if (!interrupted_ && last_output_step_ != sim_->steps()) output_frame();
  }

  void summary() const {
    const DeviceInfo& info = sim_->device().info();
    // The state's fingerprint: equal on every run of the same scene, steps and backend.
    const Result<std::uint64_t> hash = sim_->state_hash();
    const std::uint64_t steps = sim_->steps();
    const double rate = step_seconds_ > 0.0 ? static_cast<double>(steps) / step_seconds_ : 0.0;
    const double particle_rate = rate * sim_->particle_count();
    fmt::print("motes: {}\n", interrupted_ ? "interrupted (Ctrl-C)" : "done");
    fmt::print("  {:<16}{} {}: {}{}\n", "device", info.backend, info.index, info.name,
               info.detail.empty() ? "" : fmt::format(" ({})", info.detail));
    fmt::print("  {:<16}{}\n", "particles", sim_->particle_count());
    fmt::print("  {:<16}{}\n", "bodies", sim_->body_count());
    fmt::print("  {:<16}{} of {}\n", "steps", steps, total_);
    fmt::print("  {:<16}{:.6g} s\n", "simulated time", sim_->time());
    if (hash) fmt::print("  {:<16}{:016x}\n", "state hash", hash.value());
    fmt::print("  {:<16}{} (scene, device and upload)\n", "setup", format_seconds(setup_seconds_));
    fmt::print("  {:<16}{} (stepping {}, checks and output {})\n", "wall time",
               format_seconds(wall_seconds_), format_seconds(step_seconds_),
               format_seconds(output_seconds_));
    fmt::print("  {:<16}{} steps/s, {} particle-steps/s (stepping only)\n", "speed",
               format_si(rate), format_si(particle_rate));
    if (writer_) {
      fmt::print("  {:<16}{} written to {}\n", "frames", writer_->frames(), writer_->main_path());
    } else {
      fmt::print("  {:<16}none written (--format none)\n", "frames");
    }
    if (render_) fmt::print("  {:<16}{}\n", "pictures", render_summary(*render_));
    std::fflush(stdout);
  }

  const RunArgs& args_;
  std::string scene_name_;
  std::unique_ptr<Simulation> sim_;
  std::unique_ptr<FrameWriter> writer_;
  std::unique_ptr<render::RenderOutput> render_;
  std::uint64_t total_ = 0;
  std::uint64_t every_ = 1;
  std::uint64_t last_output_step_ = 0;
  bool interrupted_ = false;
  double setup_seconds_ = 0.0;
  double wall_seconds_ = 0.0;
  double step_seconds_ = 0.0;
  double output_seconds_ = 0.0;
};

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
  sub->add_option("--threads", args->threads,
                  "OpenMP backend threads (default: OMP_NUM_THREADS or every core)")
      ->check(whole_number_of<int>(1, kMaxThreads));
  sub->add_option("--render", args->render_dir,
                  "also draw every frame as a PNG in this directory, and an MP4 when ffmpeg is "
                  "installed (docs/rendering.md)");
  add_render_options(sub, args->render);
  sub->callback([args] { Runner(*args).run(); });
}

}  // namespace motes::cli
