// `motes view SCENE`: the simulation stepped in real time and drawn by the Vulkan viewer, in a
// window or offscreen (docs/viewer.md).
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "cli_util.h"
#include "commands.h"
#include "motes/devices.h"
#include "motes/render.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#ifdef MOTES_HAVE_VIEWER
#include "motes/viewer.h"
#endif

namespace motes::cli {

namespace {

struct ViewArgs {
  std::string scene;
  std::string backend = "auto";
  int device = -1;
  int threads = 0;
  std::string size = "1280x720";
  std::uint64_t frames = 0;
  std::string screenshot;
  bool offscreen = false;
  std::string color_by = "body";
};

#ifdef MOTES_HAVE_VIEWER

constexpr double kFrameRate = 60.0;
volatile std::sig_atomic_t g_stop = 0;

extern "C" void on_stop_signal(int /*signal*/) { g_stop = 1; }

using Clock = std::chrono::steady_clock;

std::unique_ptr<Simulation> make_simulation(const Scene& scene, const ViewArgs& args) {
  DeviceOptions options;
  options.cpu_threads = args.threads;
  Result<std::unique_ptr<Device>> device = open_device(args.backend, args.device, options);
  if (!device) fail(device.message());
  Result<std::unique_ptr<Simulation>> sim = Simulation::create(scene, std::move(device.value()));
  if (!sim) fail(sim.message());
  return std::move(sim.value());
}

Snapshot must_snapshot(Simulation& sim) {
  Result<Snapshot> s = sim.snapshot();
  if (!s) fail(s.message());
  return std::move(s.value());
}

void must_step(Simulation& sim, std::uint64_t steps) {
  if (steps == 0) return;
  if (Status s = sim.step(steps); !s) fail(s.message());
}

void must_write(const std::string& path, const render::Image& image) {
  if (Status s = render::write_png(path, image); !s) fail(s.message());
}

/// The next free motes-view-NNN.png in the current directory.
std::string numbered_screenshot() {
  for (int i = 1;; ++i) {
    std::string name = fmt::format("motes-view-{:03d}.png", i);
    std::error_code ec;
    if (!std::filesystem::exists(name, ec)) return name;
  }
}

/// Steps per displayed frame: 1/60 s of simulated time in whole steps (as `motes bench
/// --workload realtime`).
std::uint64_t frame_steps(double dt) {
  return static_cast<std::uint64_t>(std::max<long long>(1, std::llround(1.0 / (kFrameRate * dt))));
}

void view_offscreen(const ViewArgs& args, const Scene& scene, render::Size size,
                    const viewer::Style& style, const render::Camera& camera,
                    std::unique_ptr<Simulation> sim, const Snapshot& first) {
  if (args.frames == 0) fail("--offscreen needs --frames N (how many frames to draw)");
  viewer::Offscreen out(size, style, first);
  const std::uint64_t steps = frame_steps(scene.settings.dt);
  double step_s = 0.0, draw_s = 0.0;
  const render::Image* image = nullptr;
  for (std::uint64_t f = 0; f < args.frames && g_stop == 0; ++f) {
    const auto t0 = Clock::now();
    must_step(*sim, steps);
    const Snapshot frame = must_snapshot(*sim);
    const auto t1 = Clock::now();
    image = &out.draw(camera, frame);
    step_s += std::chrono::duration<double>(t1 - t0).count();
    draw_s += seconds_since(t1);
  }
  if (image != nullptr && !args.screenshot.empty()) must_write(args.screenshot, *image);
  const double frames = static_cast<double>(args.frames);
  fmt::print(
      "motes view: {} frames of {} steps, {} particles on {}, drawn offscreen on {}: {:.2f} ms "
      "step and {:.2f} ms draw a frame{}\n",
      args.frames, steps, sim->particle_count(), sim->device().info().backend, out.device_name(),
      1e3 * step_s / frames, 1e3 * draw_s / frames,
      args.screenshot.empty() ? "" : fmt::format("; picture {}", args.screenshot));
  std::fflush(stdout);
}

void view_window(const ViewArgs& args, render::Size size, viewer::Style style,
                 const render::Camera& camera, std::unique_ptr<Simulation> sim, Snapshot frame) {
  const std::string name = std::filesystem::path(args.scene).filename().string();
  std::unique_ptr<viewer::Window> window;
  try {
    window = std::make_unique<viewer::Window>(size, "motes view: " + name, style, frame);
  } catch (const viewer::NoDisplay& e) {
    sim.reset();  // the compute device goes before the exit handlers
    fmt::print(stderr, "motes view: no display ({}); use --offscreen\n", e.what());
    std::fflush(stderr);
    std::exit(1);
  }
  const std::string backend = sim->device().info().backend;
  viewer::Orbit orbit(camera);
  std::uint64_t steps = frame_steps(sim->settings().dt);
  bool paused = false, slow = false;
  double owed_steps = 0.0;
  std::uint64_t shown = 0;
  // Title statistics over about half a second.
  auto window_start = Clock::now();
  int window_frames = 0;
  double window_step = 0.0, window_draw = 0.0, window_simulated = 0.0;
  for (;;) {
    const auto frame_start = Clock::now();
    const viewer::Input in = window->poll();
    if (in.quit || g_stop != 0) break;
    orbit.orbit(in.orbit_x, in.orbit_y);
    orbit.pan(in.pan_x, in.pan_y, window->size());
    orbit.zoom(in.zoom);
    if (in.pause) paused = !paused;
    if (in.slow_motion) slow = !slow;
    if (in.reset) {
      Result<Scene> reloaded = load_scene_file(args.scene);
      if (!reloaded) {
        fmt::print(stderr, "motes view: reset: {}\n", reloaded.message());
      } else {
        Result<std::unique_ptr<Simulation>> made =
            Simulation::create(reloaded.value(), Simulation::take_device(std::move(sim)));
        if (!made) fail(made.message());
        sim = std::move(made.value());
        steps = frame_steps(sim->settings().dt);
        frame = must_snapshot(*sim);
        style.look = render::look_from_scene(reloaded.value());
        window->restyle(style, frame);
        owed_steps = 0.0;
      }
    }
    std::uint64_t advance = 0;
    if (!paused || in.step) {
      owed_steps += static_cast<double>(steps) * (slow && !in.step ? 0.25 : 1.0);
      advance = static_cast<std::uint64_t>(owed_steps);
      owed_steps -= static_cast<double>(advance);
    }
    const auto t0 = Clock::now();
    if (advance > 0) {
      must_step(*sim, advance);
      frame = must_snapshot(*sim);
    }
    const auto t1 = Clock::now();
    render::Image picture;
    window->draw(orbit.camera(), frame, in.screenshot ? &picture : nullptr);
    if (in.screenshot) {
      const std::string file = numbered_screenshot();
      must_write(file, picture);
      fmt::print("motes view: picture {}\n", file);
      std::fflush(stdout);
    }
    const double step_s = std::chrono::duration<double>(t1 - t0).count();
    const double draw_s = seconds_since(t1);
    ++shown;
    ++window_frames;
    window_step += step_s;
    window_draw += draw_s;
    window_simulated += static_cast<double>(advance) * sim->settings().dt;
    const double elapsed = seconds_since(window_start);
    if (elapsed >= 0.5 || shown == 1) {
      const double fps = window_frames / elapsed;
      const double factor = window_simulated / elapsed;
      const bool behind = !paused && window_step / window_frames > 1.0 / kFrameRate;
      window->set_title(fmt::format(
          "motes view: {} | {:.0f} fps | step {:.1f} ms, draw {:.1f} ms | {:.2f}x real time{} | "
          "{} particles | {}{}{}",
          name, fps, 1e3 * window_step / window_frames, 1e3 * window_draw / window_frames, factor,
          behind ? " (slower than real time)" : "", sim->particle_count(), backend,
          paused ? " | paused" : "", slow ? " | slow motion x0.25" : ""));
      window_start = Clock::now();
      window_frames = 0;
      window_step = window_draw = window_simulated = 0.0;
    }
    if (args.frames > 0 && shown >= args.frames) break;
    // Real time: a frame lasts at least 1/60 s (longer when stepping and drawing take longer).
    std::this_thread::sleep_until(frame_start +
                                  std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(1.0 / kFrameRate)));
  }
  if (!args.screenshot.empty()) {
    render::Image picture;
    window->draw(orbit.camera(), frame, &picture);
    must_write(args.screenshot, picture);
  }
  fmt::print("motes view: {} frames shown, {} particles on {}, drawn on {}{}\n", shown,
             sim->particle_count(), backend, window->device_name(),
             args.screenshot.empty() ? "" : fmt::format("; picture {}", args.screenshot));
  std::fflush(stdout);
  window.reset();
}

void view(const ViewArgs& args) {
  Result<render::Size> size = render::parse_size(args.size);
  if (!size) fail(size.message());
  Result<render::ColorBy> color_by = render::parse_color_by(args.color_by);
  if (!color_by) fail(color_by.message());
  if (!args.offscreen) {
    const char* display = std::getenv("DISPLAY");
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if ((display == nullptr || *display == '\0') && (wayland == nullptr || *wayland == '\0')) {
      fmt::print(stderr, "motes view: no display (DISPLAY is not set); use --offscreen\n");
      std::fflush(stderr);
      std::exit(1);
    }
  }
  Result<Scene> scene = load_scene_file(args.scene);
  if (!scene) fail(scene.message());
  std::unique_ptr<Simulation> sim = make_simulation(scene.value(), args);
  Snapshot first = must_snapshot(*sim);
  viewer::Style style;
  style.look = render::look_from_scene(scene.value());
  style.color_by = color_by.value();
  const render::Camera camera =
      scene->camera ? render::camera_from_spec(*scene->camera)
                    : render::fit_camera(first.particle_pos, style.look.up, size.value(), 35.0f,
                                         style.look.ground_height);
  std::signal(SIGTERM, on_stop_signal);
  std::signal(SIGINT, on_stop_signal);
  if (args.offscreen) {
    view_offscreen(args, scene.value(), size.value(), style, camera, std::move(sim), first);
  } else {
    view_window(args, size.value(), style, camera, std::move(sim), std::move(first));
  }
}

#else

void view(const ViewArgs& /*args*/) {
  fail(
      "motes view needs the Vulkan viewer, which this build lacks (MOTES_WITH_VULKAN=OFF or "
      "Vulkan not found)");
}

#endif

}  // namespace

void add_view_command(CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* sub = app.add_subcommand(
      "view", "Watch a scene in a window while it runs in real time (or draw it offscreen)");
  sub->add_option("SCENE", args->scene, "scene file (JSON)")->required();
  sub->add_option("--backend", args->backend, "backend to run on (auto: the first with a device)")
      ->check(CLI::IsMember({"auto", "openmp", "cuda", "vulkan"}))
      ->capture_default_str();
  sub->add_option("--device", args->device, "device index within the backend (motes devices)")
      ->check(whole_number_of<int>(0));
  sub->add_option("--threads", args->threads, "OpenMP backend threads")
      ->check(whole_number_of<int>(1, kMaxThreads));
  sub->add_option("--size", args->size, "window or picture size in pixels, WIDTHxHEIGHT")
      ->capture_default_str();
  sub->add_option("--frames", args->frames, "stop after this many frames (default: until closed)")
      ->check(whole_number(1));
  sub->add_option("--screenshot", args->screenshot, "write the last frame's picture as a PNG file");
  sub->add_flag("--offscreen", args->offscreen,
                "draw without a window (needs --frames; for machines without a display)");
  sub->add_option("--color-by", args->color_by,
                  fmt::format("particle colours: {}", render::color_by_names()))
      ->capture_default_str();
  sub->callback([args] { view(*args); });
}

}  // namespace motes::cli
