// Options shared by `motes run --render` and `motes render`: size, colours, frame rate, video.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "motes/render.h"
#include "motes/render_output.h"
#include "motes/scene.h"
#include "motes/simulation.h"

namespace motes::cli {

struct RenderArgs {
  std::string size = "1280x720";
  std::string color_by = "body";
  double fps = 0.0;  ///< 0: from the frame interval
  bool no_video = false;
  bool no_shadows = false;
};

/// Adds --size, --color-by, --fps, --no-video and --no-shadows to `sub`.
void add_render_options(CLI::App* sub, RenderArgs& args);

/// Settings from the options, the scene's look and camera (or one fitted to `first_frame`);
/// exits through fail() on bad values.
/// The points a fitted camera frames at the start of a run: the particles, less an emitter's
/// waiting ones (far below its nozzle), and each emitter's nozzle.
std::vector<shared::vec4> camera_points(const Simulation& sim, const Scene& scene, Snapshot first);

render::RenderSettings render_settings(const RenderArgs& args, const render::SceneLook& look,
                                       const std::optional<CameraSpec>& camera,
                                       const std::vector<shared::vec4>& first_frame);

/// Opens the PNG + video output in `dir` at --fps or the rate for `interval` simulated seconds
/// between frames, and tells the user what will be written; exits through fail() on errors.
std::unique_ptr<render::RenderOutput> open_render_output(const RenderArgs& args,
                                                         render::RenderSettings settings,
                                                         const std::string& dir, double interval,
                                                         bool camera_from_scene);

/// The summary line about the pictures written.
std::string render_summary(const render::RenderOutput& output);

}  // namespace motes::cli
