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
#include <optional>
#include <string>
#include <thread>

#include "cli_util.h"
#include "commands.h"
#include "motes/devices.h"
#include "motes/render.h"
#include "motes/render_output.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#ifdef MOTES_HAVE_VIEWER
#include "motes/view_pick.h"
#include "motes/viewer.h"
#include "render_args.h"
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
  std::string input;
  std::string save_state;
  std::string record;
  bool staged = false;
  bool no_shadows = false;
};

#ifdef MOTES_HAVE_VIEWER

constexpr double kFrameRate = 60.0;
/// The run's guards (Simulation::check_motion: tunnelling, a runaway) every this many frames
/// stepped: half a second of real time, as `motes run` checks at its frames.
constexpr std::uint64_t kGuardFrames = 30;
/// The most grid cells, and the most contacts, a wireframe draws (W, C): made on the host each
/// frame, they are a look at a small scene or part of one.
constexpr std::size_t kWireframeLimit = 200000;
volatile std::sig_atomic_t g_stop = 0;

extern "C" void on_stop_signal(int /*signal*/) { g_stop = 1; }

using Clock = std::chrono::steady_clock;

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

/// The next free motes-view-NNN.EXT (png, mp4) in the current directory.
std::string numbered_file(const char* ext) {
  for (int i = 1;; ++i) {
    std::string name = fmt::format("motes-view-{:03d}.{}", i, ext);
    std::error_code ec;
    if (!std::filesystem::exists(name, ec)) return name;
  }
}

/// Steps per displayed frame: 1/60 s of simulated time in whole steps (as `motes bench
/// --workload realtime`).
std::uint64_t frame_steps(double dt) {
  return static_cast<std::uint64_t>(std::max<long long>(1, std::llround(1.0 / (kFrameRate * dt))));
}

/// The ray from the camera through drawable pixel (x, y) (pixel centres at i + 0.5), as the
/// viewer's shaders and the headless renderer cast it; not normalized: its component along the
/// camera's forward axis is 1.
Eigen::Vector3f pixel_ray(const render::Camera& camera, render::Size size, float x, float y) {
  const Eigen::Vector3f forward = (camera.target - camera.position).normalized();
  const Eigen::Vector3f right = forward.cross(camera.up).normalized();
  const Eigen::Vector3f view_up = right.cross(forward);
  const float half_w = 0.5f * static_cast<float>(size.width);
  const float half_h = 0.5f * static_cast<float>(size.height);
  const float focal = half_h / std::tan(0.5f * camera.fov_degrees * 3.14159265f / 180.0f);
  return forward + (right * (x - half_w) - view_up * (y - half_h)) / focal;
}

/// Pick and drag (Shift + left button, docs/viewer.md): the nearest sphere of a dynamic body
/// under the cursor, picked through a grid of the last snapshot's particles made on the host
/// (motes/view_pick.h), is pulled towards the point under the cursor on the plane through it that
/// faces the camera.
class Grab {
 public:
  /// Seconds in which the pull would close the gap, and the fastest pull (m/s).
  static constexpr float kPullTime = 0.1f;
  static constexpr float kMaxSpeed = 5.0f;

  /// Picks at the cursor; false when the ray meets no dynamic particle.
  bool start(const Simulation& sim, const Snapshot& frame, const render::Camera& camera,
             render::Size size, float x, float y) {
    active_ = false;
    const Eigen::Vector3f eye = camera.position;
    const Eigen::Vector3f d = pixel_ray(camera, size, x, y);
    // Static bodies stay where they are, and so does a pinned particle of a cloth or rope
    // (inverse mass 0 without a body state).
    const viewer::Pickable pickable = [&](std::uint32_t i) {
      const std::uint32_t body = frame.particle_body[i];
      if (body >= sim.bodies().size() || sim.bodies()[body].kind == BodyKind::Static) return false;
      return sim.bodies()[body].has_body_state() || frame.particle_vel[i].w != 0.0f;
    };
    const viewer::PickHit hit = viewer::PickGrid(frame.particle_pos, pickable).pick(eye, d);
    if (!hit.hit) return false;
    particle_ = hit.particle;
    body_ = frame.particle_body[particle_];
    const shared::vec4& p = frame.particle_pos[particle_];
    inverse_mass_ = frame.particle_vel[particle_].w;
    depth_ = (Eigen::Vector3f(p.x, p.y, p.z) - eye).dot((camera.target - eye).normalized());
    active_ = true;
    return true;
  }

  /// Lets go. A held soft-body, cloth or rope particle gets its mass back (`sim`: the simulation
  /// it was grabbed in; null after a reset, which made a new one).
  void stop(Simulation* sim) {
    if (active_ && pinned_ && sim != nullptr) {
      Snapshot state = must_snapshot(*sim);
      state.particle_vel[particle_].w = inverse_mass_;
      if (Status s = sim->write_state(state); !s) fail(s.message());
    }
    active_ = pinned_ = false;
  }
  [[nodiscard]] bool active() const { return active_; }
  [[nodiscard]] std::uint32_t body() const { return body_; }

  /// Before a step: the velocity that pulls the grabbed point towards the cursor's point, given
  /// to the whole rigid body (set_body_velocities: its spin is left as it is) or to the grabbed
  /// particle alone, which is also moved by what that velocity covers in the frame (a soft
  /// body's, cloth's or rope's: write_state).
  void pull(Simulation& sim, const Snapshot& frame, const render::Camera& camera, render::Size size,
            float x, float y, double frame_seconds) {
    if (!active_) return;
    const Eigen::Vector3f eye = camera.position;
    const Eigen::Vector3f target = eye + depth_ * pixel_ray(camera, size, x, y);
    const shared::vec4& p = frame.particle_pos[particle_];
    Eigen::Vector3f v = (target - Eigen::Vector3f(p.x, p.y, p.z)) / kPullTime;
    if (v.norm() > kMaxSpeed) v *= kMaxSpeed / v.norm();
    const BodyInfo& info = sim.bodies()[body_];
    if (info.has_body_state() || info.free_sphere) {
      std::vector<Eigen::Vector3d> velocity(frame.body_vel.size());
      for (std::size_t b = 0; b < velocity.size(); ++b) {
        const shared::vec4& u = frame.body_vel[b];
        velocity[b] = sim.bodies()[b].kind == BodyKind::Static
                          ? Eigen::Vector3d::Zero()
                          : Eigen::Vector3d(Eigen::Vector3f(u.x, u.y, u.z).cast<double>());
      }
      velocity[body_] = v.cast<double>();
      if (Status s = sim.set_body_velocities(velocity); !s) fail(s.message());
    } else {
      // Held like a pinned particle (inverse mass 0, so that its links cannot pull it back) and
      // moved by what the velocity covers in the coming frame: its links drag the others.
      Snapshot state = frame;
      state.particle_vel[particle_].w = 0.0f;
      pinned_ = true;
      const Eigen::Vector3f moved = v * static_cast<float>(frame_seconds);
      shared::vec4& q = state.particle_pos[particle_];
      q.x += moved.x();
      q.y += moved.y();
      q.z += moved.z();
      state.particle_vel[particle_].x = v.x();
      state.particle_vel[particle_].y = v.y();
      state.particle_vel[particle_].z = v.z();
      if (Status s = sim.write_state(state); !s) fail(s.message());
    }
  }

 private:
  bool active_ = false;
  bool pinned_ = false;        ///< a soft-body, cloth or rope particle made massless while held
  float inverse_mass_ = 0.0f;  ///< its own
  std::uint32_t particle_ = 0;
  std::uint32_t body_ = 0;
  float depth_ = 0.0f;  ///< the grabbed point's distance along the camera's forward axis
};

/// Video of the displayed frames (V, --record FILE) through ffmpeg, as `motes render` writes its
/// videos (render::VideoEncoder), at 60 frames per second: the frame rate of real time.
class Recorder {
 public:
  [[nodiscard]] bool on() const { return video_ != nullptr; }

  /// Starts recording into `path`; without ffmpeg, says so and records nothing (`must`: fails).
  void start(const std::string& path, render::Size size, bool must) {
    const std::optional<std::string> ffmpeg = render::find_ffmpeg();
    if (!ffmpeg) {
      const std::string why = "cannot record: no ffmpeg (Debian: apt-get install ffmpeg)";
      if (must) fail(why);
      fmt::print(stderr, "motes view: {}\n", why);
      return;
    }
    Result<std::unique_ptr<render::VideoEncoder>> v =
        render::VideoEncoder::open(*ffmpeg, path, size, kFrameRate);
    if (!v) {
      if (must) fail(v.message());
      fmt::print(stderr, "motes view: {}\n", v.message());
      return;
    }
    video_ = std::move(v.value());
    size_ = size;
    fmt::print("motes view: recording {}\n", path);
    std::fflush(stdout);
  }

  /// Adds a displayed frame; a window resized while recording ends the recording.
  void add(const render::Image& picture) {
    if (!video_) return;
    if (picture.width != size_.width || picture.height != size_.height) {
      fmt::print(stderr, "motes view: the window changed size; recording stopped\n");
      stop();
      return;
    }
    if (Status s = video_->add_frame(picture); !s) {
      fmt::print(stderr, "motes view: {}\n", s.message());
      stop();
    }
  }

  void stop() {
    if (!video_) return;
    const Status s = video_->finish();
    if (!s) {
      fmt::print(stderr, "motes view: {}\n", s.message());
    } else {
      fmt::print("motes view: video {} ({} frames)\n", video_->path(), video_->frames());
    }
    std::fflush(stdout);
    video_.reset();
  }

  ~Recorder() { stop(); }
  Recorder() = default;
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

 private:
  std::unique_ptr<render::VideoEncoder> video_;
  render::Size size_;
};

/// Where frames go: a window (with the person's input) or an offscreen picture (no input but the
/// script's). One loop drives both, so scripted input does the same offscreen as in a window.
/// Both draw staged (a snapshot each frame) or, attached to a simulation on their own Vulkan
/// device, zero copy (docs/viewer.md); restyle (a new scene) goes back to staged.
class Surface {
 public:
  virtual ~Surface() = default;
  virtual viewer::Input poll() = 0;
  [[nodiscard]] virtual render::Size size() const = 0;
  /// `frame`: the particles on the staged path; ignored (may be null) when attached.
  virtual void draw(const render::Camera& camera, const Snapshot* frame, render::Image* shot) = 0;
  virtual void restyle(const viewer::Style& style, const Snapshot& first) = 0;
  [[nodiscard]] virtual Result<std::unique_ptr<Device>> open_compute_device() const = 0;
  virtual std::string attach(Simulation& sim, const Snapshot& first) = 0;
  [[nodiscard]] virtual bool attached() const = 0;
  [[nodiscard]] virtual const char* path() const = 0;
  virtual void set_title(const std::string& title) = 0;
  virtual void set_overlay(const viewer::Segments& segments) = 0;
  virtual void set_shadows(bool on) = 0;
  [[nodiscard]] virtual const std::string& device_name() const = 0;
  [[nodiscard]] virtual int device_index() const = 0;
  [[nodiscard]] virtual bool real_time() const = 0;
};

/// Surface over a viewer::Window or viewer::Offscreen (the same calls).
template <class Target, bool kRealTime>
class TargetSurface : public Surface {
 public:
  explicit TargetSurface(std::unique_ptr<Target> target) : target_(std::move(target)) {}
  void restyle(const viewer::Style& style, const Snapshot& first) override {
    target_->restyle(style, first);
  }
  [[nodiscard]] Result<std::unique_ptr<Device>> open_compute_device() const override {
    return target_->open_compute_device();
  }
  std::string attach(Simulation& sim, const Snapshot& first) override {
    return target_->attach(sim, first);
  }
  [[nodiscard]] bool attached() const override { return target_->attached(); }
  [[nodiscard]] const char* path() const override { return target_->path(); }
  void set_overlay(const viewer::Segments& segments) override { target_->set_overlay(segments); }
  void set_shadows(bool on) override { target_->set_shadows(on); }
  [[nodiscard]] const std::string& device_name() const override { return target_->device_name(); }
  [[nodiscard]] int device_index() const override { return target_->device_index(); }
  [[nodiscard]] bool real_time() const override { return kRealTime; }

 protected:
  std::unique_ptr<Target> target_;
};

class WindowSurface final : public TargetSurface<viewer::Window, true> {
 public:
  using TargetSurface::TargetSurface;
  viewer::Input poll() override { return target_->poll(); }
  [[nodiscard]] render::Size size() const override { return target_->size(); }
  void draw(const render::Camera& camera, const Snapshot* frame, render::Image* shot) override {
    target_->draw(camera, frame, shot);
  }
  void set_title(const std::string& title) override { target_->set_title(title); }
};

class OffscreenSurface final : public TargetSurface<viewer::Offscreen, false> {
 public:
  OffscreenSurface(render::Size size, int wanted_device)
      : TargetSurface(std::make_unique<viewer::Offscreen>(size, wanted_device)), size_(size) {}
  viewer::Input poll() override { return {}; }
  [[nodiscard]] render::Size size() const override { return size_; }
  void draw(const render::Camera& camera, const Snapshot* frame, render::Image* shot) override {
    const render::Image& image = target_->draw(camera, frame);
    if (shot != nullptr) *shot = image;
  }
  void set_title(const std::string& /*title*/) override {}

 private:
  render::Size size_;
};

void run_view(const ViewArgs& args, Surface& surface, viewer::Style style,
              const render::Camera& camera, std::unique_ptr<Simulation>& sim, Snapshot frame,
              const std::optional<viewer::Script>& script) {
  const std::string name = std::filesystem::path(args.scene).filename().string();
  const std::string backend = sim->device().info().backend;
  // Zero copy or the CUDA copy: the picture comes from the device; `frame` is read back only
  // when the host needs it (picking and pulling), and is stale in between.
  const bool on_device = surface.attached();
  const std::string path = surface.path();
  bool frame_current = true;
  auto current_frame = [&]() -> const Snapshot& {
    if (!frame_current) frame = must_snapshot(*sim);
    frame_current = true;
    return frame;
  };
  viewer::Orbit orbit(camera);
  std::uint64_t steps = frame_steps(sim->settings().dt);
  bool paused = false, slow = false;
  // The wireframes (W: grid cells, C: contacts), made from the host's copy of the state.
  bool grid_wireframe = false, contact_wireframe = false;
  bool overlay_shown = false, overlay_truncated_said = false;
  // The particles' shadows on the ground (H; --no-shadows starts without them).
  bool shadows = !args.no_shadows;
  surface.set_shadows(shadows);
  // The guards: the warnings seen (each printed once) and the first failure, which pauses the run.
  std::uint64_t stepped_frames = 0, guard_warnings = 0;
  std::string last_warning, guard_failure;
  double owed_steps = 0.0;
  std::uint64_t shown = 0;
  double total_step = 0.0, total_copy = 0.0, total_draw = 0.0;
  // Title statistics over about half a second.
  auto window_start = Clock::now();
  int window_frames = 0;
  double window_step = 0.0, window_draw = 0.0, window_simulated = 0.0;
  render::Image last_picture;
  Grab grab;
  Recorder recorder;
  if (!args.record.empty()) recorder.start(args.record, surface.size(), true);
  for (;;) {
    const auto frame_start = Clock::now();
    viewer::Input in = surface.poll();
    if (script) in.merge(script->at(shown));
    if (in.quit || g_stop != 0) break;
    orbit.orbit(in.orbit_x, in.orbit_y);
    orbit.pan(in.pan_x, in.pan_y, surface.size());
    orbit.zoom(in.zoom);
    if (in.record) {
      if (recorder.on()) {
        recorder.stop();
      } else {
        recorder.start(numbered_file("mp4"), surface.size(), false);
      }
    }
    if (in.pause) paused = !paused;
    if (in.grid_wireframe) grid_wireframe = !grid_wireframe;
    if (in.contact_wireframe) contact_wireframe = !contact_wireframe;
    if (in.shadows) {
      shadows = !shadows;
      surface.set_shadows(shadows);
    }
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
        guard_failure.clear();  // a new run: its guards start again
        last_warning.clear();
        steps = frame_steps(sim->settings().dt);
        frame = must_snapshot(*sim);
        frame_current = true;
        style.look = render::look_from_scene(reloaded.value());
        surface.restyle(style, frame);
        if (on_device) {  // the new simulation's buffers
          if (std::string why = surface.attach(*sim, frame); !why.empty()) fail(why);
        }
        owed_steps = 0.0;
        grab.stop(nullptr);
      }
    }
    if (in.grab_start) {
      if (grab.start(*sim, current_frame(), orbit.camera(), surface.size(), in.cursor_x,
                     in.cursor_y)) {
        fmt::print("motes view: grabbed {}\n", sim->bodies()[grab.body()].name);
      } else {
        fmt::print("motes view: nothing to grab at ({:.0f}, {:.0f})\n", in.cursor_x, in.cursor_y);
      }
      std::fflush(stdout);
    }
    if (!in.grabbing) grab.stop(sim.get());
    std::uint64_t advance = 0;
    if (!paused || in.step) {
      owed_steps += static_cast<double>(steps) * (slow && !in.step ? 0.25 : 1.0);
      advance = static_cast<std::uint64_t>(owed_steps);
      owed_steps -= static_cast<double>(advance);
    }
    const bool last = args.frames > 0 && shown + 1 >= args.frames;
    const auto t0 = Clock::now();
    if (advance > 0) {
      if (grab.active()) {
        grab.pull(*sim, current_frame(), orbit.camera(), surface.size(), in.cursor_x, in.cursor_y,
                  static_cast<double>(advance) * sim->settings().dt);
      }
      must_step(*sim, advance);
      // Stepping alone (a backend may queue steps and return before they are done).
      if (Status s = sim->device().synchronize(); !s) fail(s.message());
      frame_current = false;
      // Every kGuardFrames frames stepped, and at the last frame of a run with a frame limit.
      if ((++stepped_frames % kGuardFrames == 0 || last) && guard_failure.empty()) {
        Result<MotionReport> r = sim->check_motion();
        if (!r) {  // unstable: the run stops here, paused, and says why
          guard_failure = r.message();
          paused = true;
          fmt::print(stderr, "motes view: guard: {} (paused)\n", guard_failure);
        } else if (!r.value().warning.empty() && r.value().warning != last_warning) {
          last_warning = r.value().warning;
          ++guard_warnings;
          fmt::print(stderr, "motes view: guard warning: {}\n", last_warning);
        }
        std::fflush(stderr);
      }
    }
    if (in.grab_end) {
      grab.stop(sim.get());
      frame_current = false;
    }
    const auto t1 = Clock::now();
    if (!on_device) current_frame();  // the staged path draws from the host's copy
    if (grid_wireframe || contact_wireframe) {
      viewer::Segments lines;
      if (grid_wireframe) {
        lines = viewer::grid_cell_segments(current_frame(), sim->step_params().inv_cell_size,
                                           kWireframeLimit);
      }
      if (contact_wireframe) {
        viewer::Segments contacts = viewer::contact_segments(current_frame(), kWireframeLimit);
        lines.ends.insert(lines.ends.end(), contacts.ends.begin(), contacts.ends.end());
        lines.colors.insert(lines.colors.end(), contacts.colors.begin(), contacts.colors.end());
        lines.truncated = lines.truncated || contacts.truncated;
      }
      if (lines.truncated && !overlay_truncated_said) {
        fmt::print(stderr, "motes view: the wireframe shows its first {} cells or contacts\n",
                   kWireframeLimit);
        overlay_truncated_said = true;
      }
      surface.set_overlay(lines);
      overlay_shown = true;
    } else if (overlay_shown) {
      surface.set_overlay({});
      overlay_shown = false;
    }
    const auto t2 = Clock::now();
    const bool keep = in.screenshot || (last && !args.screenshot.empty()) || recorder.on();
    render::Image picture;
    surface.draw(orbit.camera(), on_device ? nullptr : &frame, keep ? &picture : nullptr);
    if (in.screenshot) {
      const std::string file = numbered_file("png");
      must_write(file, picture);
      fmt::print("motes view: picture {}\n", file);
      std::fflush(stdout);
    }
    recorder.add(picture);
    if (keep) last_picture = std::move(picture);
    const double step_s = std::chrono::duration<double>(t1 - t0).count();
    const double copy_s = std::chrono::duration<double>(t2 - t1).count();
    const double draw_s = seconds_since(t2);
    ++shown;
    total_step += step_s;
    total_copy += copy_s;
    total_draw += draw_s;
    ++window_frames;
    window_step += step_s;
    window_draw += copy_s + draw_s;
    window_simulated += static_cast<double>(advance) * sim->settings().dt;
    const double elapsed = seconds_since(window_start);
    if (surface.real_time() && (elapsed >= 0.5 || shown == 1)) {
      const double fps = window_frames / elapsed;
      const double factor = window_simulated / elapsed;
      const bool behind = !paused && window_step / window_frames > 1.0 / kFrameRate;
      surface.set_title(fmt::format(
          "motes view: {} | {:.0f} fps | step {:.1f} ms, draw {:.1f} ms ({}) | {:.2f}x real time{} "
          "| {} particles | {}{}{}{}",
          name, fps, 1e3 * window_step / window_frames, 1e3 * window_draw / window_frames, path,
          factor, behind ? " (slower than real time)" : "", sim->particle_count(), backend,
          paused ? " | paused" : "", slow ? " | slow motion x0.25" : "",
          !guard_failure.empty() ? " | guard: unstable, paused"
          : guard_warnings > 0   ? fmt::format(" | guard warnings: {}", guard_warnings)
                                 : std::string()));
      window_start = Clock::now();
      window_frames = 0;
      window_step = window_draw = window_simulated = 0.0;
    }
    if (last) break;
    // Real time: a frame lasts at least 1/60 s (longer when stepping and drawing take longer).
    if (surface.real_time()) {
      std::this_thread::sleep_until(frame_start +
                                    std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(1.0 / kFrameRate)));
    }
  }
  if (!args.screenshot.empty()) {
    if (last_picture.rgb.empty()) {
      surface.draw(orbit.camera(), on_device ? nullptr : &current_frame(), &last_picture);
    }
    must_write(args.screenshot, last_picture);
  }
  recorder.stop();
  grab.stop(sim.get());  // the saved state has every particle's own mass
  if (!args.save_state.empty()) {
    if (Status s = sim->save_state(args.save_state); !s) fail(s.message());
  }
  const double n = static_cast<double>(std::max<std::uint64_t>(shown, 1));
  fmt::print(
      "motes view: {} frames shown, {} particles on {}, drawn {} {}on {}: {:.2f} ms step, {:.2f} "
      "ms copy to the host and {:.2f} ms draw a frame; {}{}{}\n",
      shown, sim->particle_count(), backend, path, surface.real_time() ? "" : "offscreen ",
      surface.device_name(), 1e3 * total_step / n, 1e3 * total_copy / n, 1e3 * total_draw / n,
      !guard_failure.empty() ? "guard: unstable (paused)"
      : guard_warnings > 0   ? fmt::format("guard warnings: {}", guard_warnings)
                             : std::string("no guard warning"),
      args.screenshot.empty() ? "" : fmt::format("; picture {}", args.screenshot),
      args.save_state.empty() ? "" : fmt::format("; state {}", args.save_state));
  std::fflush(stdout);
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
  std::optional<viewer::Script> script;
  if (!args.input.empty()) {
    try {
      script = viewer::Script::load(args.input);
    } catch (const std::runtime_error& e) {
      fail(e.what());
    }
  }
  Result<Scene> scene = load_scene_file(args.scene);
  if (!scene) fail(scene.message());
  DeviceOptions options;
  options.cpu_threads = args.threads;
  Result<std::unique_ptr<Device>> device = open_device(args.backend, args.device, options);
  if (!device) fail(device.message());
  const DeviceInfo compute = device.value()->info();
  std::signal(SIGTERM, on_stop_signal);
  std::signal(SIGINT, on_stop_signal);
  if (args.offscreen && args.frames == 0 && !(script && script->quits())) {
    fail("--offscreen needs --frames N, or an --input script that quits (when to stop)");
  }
  // The viewer draws on the compute backend's Vulkan device when it can (zero copy needs one).
  const int wanted = compute.backend == "vulkan" ? compute.index : -1;
  std::unique_ptr<Surface> surface;
  if (args.offscreen) {
    surface = std::make_unique<OffscreenSurface>(size.value(), wanted);
  } else {
    const std::string name = std::filesystem::path(args.scene).filename().string();
    try {
      surface = std::make_unique<WindowSurface>(
          std::make_unique<viewer::Window>(size.value(), "motes view: " + name, wanted));
    } catch (const viewer::NoDisplay& e) {
      device.value().reset();  // the compute device goes before the exit handlers
      fmt::print(stderr, "motes view: no display ({}); use --offscreen\n", e.what());
      std::fflush(stderr);
      std::exit(1);
    }
  }
  // Zero copy (docs/viewer.md): the simulation on the viewer's own device, motes' Vulkan device
  // made on it (motes/vulkan_interop.h), so that the sphere pipeline reads its buffers.
  std::string staged_why = fmt::format("the {} backend", compute.backend);
  bool zero_copy = false;
  if (compute.backend == "vulkan") {
    if (args.staged) {
      staged_why = "--staged";
    } else if (surface->device_index() != compute.index) {
      staged_why = fmt::format("the simulation's Vulkan device {} cannot draw", compute.name);
    } else {
      // motes' own device goes first: volk's device functions are one device's at a time.
      device.value().reset();
      device = surface->open_compute_device();
      zero_copy = device.is_ok();
      if (!zero_copy) {
        staged_why = device.message();
        device = open_device(args.backend, args.device, options);
        if (!device) fail(device.message());
      }
    }
  }
  Result<std::unique_ptr<Simulation>> made =
      Simulation::create(scene.value(), std::move(device.value()));
  if (!made) fail(made.message());
  std::unique_ptr<Simulation> sim = std::move(made.value());
  Snapshot first = must_snapshot(*sim);
  viewer::Style style;
  style.look = render::look_from_scene(scene.value());
  style.color_by = color_by.value();
  surface->restyle(style, first);
  if (zero_copy) {
    if (std::string why = surface->attach(*sim, first); !why.empty()) fail(why);
  } else if (compute.backend == "cuda") {
    // The CUDA copy: into memory the viewer shares with CUDA on the same GPU, device to device.
    staged_why = args.staged ? "--staged" : surface->attach(*sim, first);
  }
  const std::string path = surface->path();
  fmt::print("motes view: drawing {}\n",
             path == "zero copy" ? "zero copy, from the simulation's own Vulkan buffers"
             : path == "CUDA copy"
                 ? "by the CUDA copy, device to device into the viewer's memory (CUDA-Vulkan "
                   "external memory)"
                 : fmt::format("staged, through the host ({})", staged_why));
  std::fflush(stdout);
  const render::Camera camera =
      scene->camera ? render::camera_from_spec(*scene->camera)
                    : render::fit_camera(camera_points(*sim, scene.value(), first), style.look.up,
                                         size.value(), 35.0f, style.look.ground_height);
  run_view(args, *surface, style, camera, sim, std::move(first), script);
  sim.reset();  // zero copy: motes' device is on the viewer's, which goes next
  surface.reset();
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
  sub->add_option("--input", args->input,
                  "scripted input: timed key, drag, wheel and quit events by frame "
                  "(docs/viewer.md)");
  sub->add_option("--save-state", args->save_state,
                  "at the end, write the state as a checkpoint (Simulation::load_state reads "
                  "it; it has no run description for motes resume)");
  sub->add_option("--record", args->record,
                  "record the displayed frames from the start as an MP4 video (ffmpeg; V stops)");
  sub->add_flag("--staged", args->staged,
                "draw from a copy of the particles through the host even where the Vulkan "
                "backend's buffers could be drawn as they are (zero copy) or CUDA could copy "
                "them on the GPU (the CUDA copy; docs/viewer.md)");
  sub->add_flag("--no-shadows", args->no_shadows,
                "start without the particles' shadows on the ground (H turns them on and off)");
  sub->add_flag(
      "--offscreen", args->offscreen,
      "draw without a window (needs --frames, or an --input script that quits; for machines "
      "without a display)");
  sub->add_option("--color-by", args->color_by,
                  fmt::format("particle colours: {}", render::color_by_names()))
      ->capture_default_str();
  sub->callback([args] { view(*args); });
}

}  // namespace motes::cli
