// The render options of `motes run` and `motes render`.
#include "render_args.h"

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>

#include "cli_util.h"

namespace motes::cli {

namespace {

CLI::Validator size_check() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        Result<render::Size> s = render::parse_size(text);
        return s ? std::string() : s.message();
      },
      "WIDTHxHEIGHT");
}

CLI::Validator color_by_check() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        Result<render::ColorBy> c = render::parse_color_by(text);
        return c ? std::string() : c.message();
      },
      fmt::format("one of: {}", render::color_by_names()));
}

}  // namespace

void add_render_options(CLI::App* sub, RenderArgs& args) {
  sub->add_option("--size", args.size, "picture size in pixels, WIDTHxHEIGHT")
      ->check(size_check())
      ->capture_default_str();
  sub->add_option("--color-by", args.color_by,
                  fmt::format("particle colours: {}", render::color_by_names()))
      ->check(color_by_check())
      ->capture_default_str();
  sub->add_option("--fps", args.fps,
                  "video frames per second, 0.01 to 1000 (default: frames per simulated second, "
                  "clamped to 1..60)")
      ->check(finite_between(0.01, 1000.0));
  sub->add_flag("--no-video", args.no_video, "PNG frames only, no MP4");
  sub->add_flag("--no-shadows", args.no_shadows, "no shadows (a little faster)");
}

std::vector<shared::vec4> camera_points(const Simulation& sim, const Scene& scene, Snapshot first) {
  sim.hide_parked(first);
  for (const FluidSpec& f : scene.fluids) {
    if (!f.emitter) continue;
    const Eigen::Vector3f p = f.emitter->position.cast<float>();
    first.particle_pos.emplace_back(p.x(), p.y(), p.z(), static_cast<float>(0.5 * f.diameter));
  }
  return std::move(first.particle_pos);
}

render::RenderSettings render_settings(const RenderArgs& args, const render::SceneLook& look,
                                       const std::optional<CameraSpec>& camera,
                                       const std::vector<shared::vec4>& first_frame) {
  Result<render::Size> size = render::parse_size(args.size);
  if (!size) fail(size.message());
  Result<render::ColorBy> color_by = render::parse_color_by(args.color_by);
  if (!color_by) fail(color_by.message());
  render::RenderSettings s;
  s.size = size.value();
  s.color_by = color_by.value();
  s.look = look;
  s.shadows = !args.no_shadows;
  s.camera = camera ? render::camera_from_spec(*camera)
                    : render::fit_camera(first_frame, look.up, s.size, 35.0f, look.ground_height);
  return s;
}

std::unique_ptr<render::RenderOutput> open_render_output(const RenderArgs& args,
                                                         render::RenderSettings settings,
                                                         const std::string& dir, double interval,
                                                         bool camera_from_scene) {
  render::FrameRate rate;
  if (args.fps > 0.0) {
    rate.fps = args.fps;
  } else {
    rate = render::frame_rate_for_interval(interval);
  }
  const render::Size size = settings.size;
  const std::string color_by = args.color_by;
  render::OutputOptions options;
  options.dir = dir;
  options.video = !args.no_video;
  options.fps = rate.fps;
  Result<std::unique_ptr<render::RenderOutput>> out =
      render::RenderOutput::open(std::move(settings), options);
  if (!out) fail(out.message());
  fmt::print("motes: rendering {}x{} pictures to {} (colour by {}, camera {})\n", size.width,
             size.height, dir, color_by,
             camera_from_scene ? "from the scene" : "fitted to the first frame");
  if (!out.value()->video_path().empty()) {
    fmt::print("motes: video {} at {:g} fps{}\n", out.value()->video_path(), rate.fps,
               rate.note.empty() ? "" : fmt::format(" ({})", rate.note));
  } else {
    fmt::print("motes: {}\n", out.value()->notice());
  }
  std::fflush(stdout);
  return std::move(out).value();
}

std::string render_summary(const render::RenderOutput& output) {
  std::string line = fmt::format("{} PNG frames in {}", output.frames(), output.dir());
  if (!output.video_path().empty()) {
    line += fmt::format(", video {}", output.video_path());
  } else {
    line += fmt::format(" ({})", output.notice());
  }
  const double per_frame =
      output.frames() > 0 ? output.seconds() / static_cast<double>(output.frames()) : 0.0;
  line += fmt::format("; {} per frame", format_seconds(per_frame));
  return line;
}

}  // namespace motes::cli
