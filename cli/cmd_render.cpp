// `motes render RESULTS`: pictures and video of frames that `motes run --out` wrote.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "cli_util.h"
#include "commands.h"
#include "motes/render.h"
#include "motes/render_output.h"
#include "motes/scene.h"
#include "render_args.h"

namespace motes::cli {

namespace {

struct RenderCommandArgs {
  std::string results;
  std::string out;
  std::string scene;
  double radius = 0.0;
  RenderArgs render;
};

/// What one pass over the frames tells: how many, the first frame interval and the lowest
/// particle bottom (where the ground goes when no scene says).
struct FramesSurvey {
  std::size_t frames = 0;
  double interval = 0.0;
  float lowest = std::numeric_limits<float>::infinity();
};

FramesSurvey survey(render::FrameReader& reader, const Eigen::Vector3f& up) {
  FramesSurvey s;
  Snapshot frame;
  double first_time = 0.0;
  while (true) {
    Result<bool> got = reader.next(frame);
    if (!got) fail(got.message());
    if (!got.value()) break;
    if (s.frames == 0) first_time = frame.time;
    if (s.frames == 1) s.interval = frame.time - first_time;
    for (const shared::vec4& p : frame.particle_pos) {
      s.lowest = std::min(s.lowest, up.dot(Eigen::Vector3f(p.x, p.y, p.z)) - p.w);
    }
    ++s.frames;
  }
  if (s.frames == 0) fail(fmt::format("'{}' holds no frames", reader.source()));
  if (Status st = reader.rewind(); !st) fail(st.message());
  return s;
}

void render_results(const RenderCommandArgs& args) {
  namespace fs = std::filesystem;
  Result<std::unique_ptr<render::FrameReader>> opened =
      render::FrameReader::open(args.results, args.radius);
  if (!opened) fail(opened.message());
  render::FrameReader& reader = *opened.value();

  render::SceneLook look;
  std::optional<CameraSpec> camera;
  if (!args.scene.empty()) {
    Result<Scene> scene = load_scene_file(args.scene);
    if (!scene) fail(scene.message());
    look = render::look_from_scene(scene.value());
    camera = scene->camera;
  }
  const FramesSurvey frames = survey(reader, look.up);
  if (args.scene.empty()) look.ground_height = frames.lowest;

  Snapshot frame;
  Result<bool> got = reader.next(frame);
  if (!got || !got.value()) fail(got ? "no frames" : got.message());
  render::RenderSettings settings = render_settings(args.render, look, camera, frame.particle_pos);
  std::error_code ec;
  const std::string out = !args.out.empty() ? args.out
                          : fs::is_directory(args.results, ec)
                              ? (fs::path(args.results) / "render").string()
                              : (fs::path(args.results).parent_path() / "render").string();
  fmt::print("motes: {}: {} frames of {} particles\n", reader.source(), frames.frames,
             frame.particle_pos.size());
  std::unique_ptr<render::RenderOutput> output = open_render_output(
      args.render, std::move(settings), out, frames.interval, camera.has_value());
  do {
    if (Status s = output->add_frame(frame); !s) fail(s.message());
    got = reader.next(frame);
    if (!got) fail(got.message());
  } while (got.value());
  if (Status s = output->finish(); !s) fail(s.message());
  fmt::print("motes: done\n  {:<16}{}\n", "pictures", render_summary(*output));
  std::fflush(stdout);
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto args = std::make_shared<RenderCommandArgs>();
  CLI::App* sub = app.add_subcommand(
      "render", "Draw the frames that motes run --out wrote as PNG pictures and an MP4 video");
  sub->add_option("RESULTS", args->results,
                  "a motes run --out directory (VTU frames with particles.pvd, or particles.csv), "
                  "or a .pvd, .vtu or .csv file")
      ->required();
  sub->add_option("--out", args->out, "directory for the pictures (default: RESULTS/render)");
  sub->add_option("--scene", args->scene,
                  "the scene file of the run: its camera, ground plane, up direction and static "
                  "bodies (default: a fitted camera, the ground under the lowest particle)");
  sub->add_option("--radius", args->radius,
                  "particle radius for CSV frames, which have none (default: half the typical "
                  "distance between neighbouring particles)")
      ->check(finite_positive());
  add_render_options(sub, args->render);
  sub->callback([args] { render_results(*args); });
}

}  // namespace motes::cli
