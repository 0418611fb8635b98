// `motes render-bench`: how fast the CPU renderer draws N particles (docs/rendering.md).
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_util.h"
#include "commands.h"
#include "motes/render.h"
#include "render_args.h"

namespace motes::cli {

namespace {

struct RenderBenchArgs {
  std::uint32_t particles = 1'000'000;
  int frames = 5;
  RenderArgs render;
};

/// A cube of particles of 1 cm on the ground, 16 bodies side by side, as a heavy frame.
Snapshot particle_block(std::uint32_t count) {
  const auto side = static_cast<std::uint32_t>(std::ceil(std::cbrt(static_cast<double>(count))));
  Snapshot s;
  s.particle_pos.reserve(count);
  const float d = 0.01f;
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint32_t x = i % side, y = (i / side) % side, z = i / (side * side);
    s.particle_pos.emplace_back(d * (static_cast<float>(x) + 0.5f),
                                d * (static_cast<float>(y) + 0.5f),
                                d * (static_cast<float>(z) + 0.5f), 0.5f * d);
    s.particle_vel.emplace_back(0.0f, -0.1f * static_cast<float>(y), 0.0f, 0.0f);
    s.particle_body.push_back(x * 16 / side);
  }
  return s;
}

void render_bench(const RenderBenchArgs& args) {
  const Snapshot frame = particle_block(args.particles);
  render::SceneLook look;
  look.ground_height = 0.0f;
  const render::RenderSettings settings =
      render_settings(args.render, look, std::nullopt, frame.particle_pos);
  render::FrameRenderer renderer(settings);
  fmt::print(
      "motes: render-bench: {} particles (a block of 1 cm spheres), {}x{}, colour by {}, "
      "shadows {}\n",
      frame.particle_pos.size(), settings.size.width, settings.size.height, args.render.color_by,
      settings.shadows ? "on" : "off");
  (void)renderer.render(frame);  // warm-up: buffers allocated, pages touched
  double best = 1e30, total = 0.0;
  for (int i = 0; i < args.frames; ++i) {
    const auto start = std::chrono::steady_clock::now();
    (void)renderer.render(frame);
    const double took = seconds_since(start);
    best = std::min(best, took);
    total += took;
  }
  const auto start = std::chrono::steady_clock::now();
  const std::string png = "render-bench.png";
  if (Status s = render::write_png(png, renderer.render(frame)); !s) fail(s.message());
  const double with_png = seconds_since(start);
  fmt::print("  {:<16}{:.1f} ms mean, {:.1f} ms best over {} frames\n", "render",
             1e3 * total / args.frames, 1e3 * best, args.frames);
  fmt::print("  {:<16}{:.1f} ms (render + PNG, written to {})\n", "with PNG", 1e3 * with_png, png);
  std::fflush(stdout);
}

}  // namespace

void add_render_bench_command(CLI::App& app) {
  auto args = std::make_shared<RenderBenchArgs>();
  CLI::App* sub =
      app.add_subcommand("render-bench", "Time the CPU renderer on a block of N particles");
  sub->add_option("--particles", args->particles, "particles to draw")
      ->check(whole_number_of<std::uint32_t>(1, 100'000'000))
      ->capture_default_str();
  sub->add_option("--frames", args->frames, "frames to time")
      ->check(whole_number_of<int>(1, 1000))
      ->capture_default_str();
  add_render_options(sub, args->render);
  sub->callback([args] { render_bench(*args); });
}

}  // namespace motes::cli
