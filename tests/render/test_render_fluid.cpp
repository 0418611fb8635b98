// Liquids in pictures (docs/rendering.md, "Colours of liquids"): a fluid particle's colour in each
// mode, and a picture of a small simulated tank whose water is blue, lighter at the surface than in
// the bulk.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "motes/devices.h"
#include "motes/render.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "render/render_support.h"

namespace motes::render {
namespace {

using motes_test::rgb_at;

constexpr float kD = 0.02f;  // the fluid particles' diameter in the made-up frames

/// Body 0 a rigid sphere, body 1 a fluid: a column of `layers` fluid particles at rest, one on
/// another from y = 0 up, then (when `spray`) one more 5 d above the column, moving at `spray`.
Snapshot fluid_column(int layers, float spray = 0.0f) {
  Snapshot s;
  s.particle_pos.emplace_back(1.0f, 0.0f, 0.0f, 0.5f * kD);
  s.particle_vel.emplace_back(0.0f, 0.0f, 0.0f, 1.0f);
  s.particle_body.push_back(0);
  for (int i = 0; i < layers; ++i) {
    s.particle_pos.emplace_back(0.0f, static_cast<float>(i) * kD, 0.0f, 0.5f * kD);
    s.particle_vel.emplace_back(0.0f, 0.0f, 0.0f, 1.0f);
    s.particle_body.push_back(1);
  }
  if (spray > 0.0f) {
    s.particle_pos.emplace_back(0.0f, static_cast<float>(layers + 4) * kD, 0.0f, 0.5f * kD);
    s.particle_vel.emplace_back(spray, 0.0f, 0.0f, 1.0f);
    s.particle_body.push_back(1);
  }
  return s;
}

SceneLook fluid_look() {
  SceneLook look;
  look.body_static = {0, 0};
  look.body_fluid = {0, 1};
  return look;
}

bool blue_dominant(const Eigen::Vector3f& c) { return c.z() > c.x() && c.z() > c.y(); }

TEST(RenderFluid, BodyColoursAreWaterDeeperDownLighterOnTopAndInSpray) {
  const int layers = 16;
  const Snapshot frame = fluid_column(layers, 4.0f);
  ParticleColors colors(ColorBy::Body, fluid_look());
  colors.observe(frame);
  const std::size_t top = layers, bottom = 1, spray = layers + 1;
  const Eigen::Vector3f surface = colors(frame, top), deep = colors(frame, bottom);
  EXPECT_TRUE(blue_dominant(surface)) << surface.transpose();
  EXPECT_TRUE(blue_dominant(deep)) << deep.transpose();
  // Lighter at the surface, darker in the bulk than the base colour; the layer under the surface
  // in between.
  EXPECT_GT(surface.sum(), water_color().sum() + 0.3f) << surface.transpose();
  EXPECT_LT(deep.sum(), 0.7f * water_color().sum()) << deep.transpose();
  EXPECT_LT(colors(frame, top - 1).sum(), surface.sum());
  EXPECT_GT(colors(frame, top - 1).sum(), deep.sum());
  // The spray above the column is its own surface, and fast: whiter than the resting surface.
  const Eigen::Vector3f fast = colors(frame, spray);
  EXPECT_GT(fast.minCoeff(), surface.minCoeff() + 0.2f) << fast.transpose();
  // The rigid sphere keeps its palette colour; unshaded gives the fluid its flat base.
  EXPECT_EQ(colors(frame, 0), body_color(0));
  EXPECT_EQ(colors.unshaded(frame, top), water_color());
  EXPECT_EQ(colors.unshaded(frame, bottom), water_color());
  EXPECT_TRUE(colors.is_fluid(frame, top));
  EXPECT_FALSE(colors.is_fluid(frame, 0));
}

TEST(RenderFluid, AFluidsOwnColourIsTheBaseOfTheSameShading) {
  const Snapshot frame = fluid_column(16);
  SceneLook look = fluid_look();
  const Eigen::Vector3f red(0.8f, 0.1f, 0.1f);
  look.body_colors = {std::nullopt, red};
  ParticleColors colors(ColorBy::Body, look);
  colors.observe(frame);
  const Eigen::Vector3f surface = colors(frame, 16), deep = colors(frame, 1);
  EXPECT_GT(surface.x(), surface.z()) << surface.transpose();
  EXPECT_GT(deep.x(), 2.0f * deep.z()) << deep.transpose();
  EXPECT_GT(surface.sum(), red.sum());
  EXPECT_LT(deep.sum(), 0.7f * red.sum());
  EXPECT_EQ(colors.unshaded(frame, 5), red);
}

TEST(RenderFluid, KindColoursFluidsWaterBlueShadedLikeWater) {
  const Snapshot frame = fluid_column(16);
  SceneLook look = fluid_look();
  look.body_colors = {std::nullopt, Eigen::Vector3f(0.8f, 0.1f, 0.1f)};  // kind ignores it
  ParticleColors colors(ColorBy::Kind, look);
  colors.observe(frame);
  EXPECT_EQ(colors.unshaded(frame, 5), water_color());
  EXPECT_TRUE(blue_dominant(colors(frame, 16)));
  EXPECT_TRUE(blue_dominant(colors(frame, 1)));
  EXPECT_GT(colors(frame, 16).sum(), colors(frame, 1).sum() + 0.3f);
  // The rigid sphere: dynamic, warm.
  const Eigen::Vector3f warm = colors(frame, 0);
  EXPECT_GT(warm.x(), warm.z() + 0.5f) << warm.transpose();
}

TEST(RenderFluid, SpeedAndHeightColoursTreatFluidAsEverythingElse) {
  Snapshot frame = fluid_column(16);
  frame.particle_vel[0] = shared::vec4(1.5f, 0.0f, 0.0f, 1.0f);  // the sphere
  frame.particle_vel[5] = shared::vec4(0.0f, 1.5f, 0.0f, 1.0f);  // a fluid particle
  frame.particle_vel[9] = shared::vec4(0.0f, 0.0f, 0.75f, 1.0f);
  for (ColorBy mode : {ColorBy::Speed, ColorBy::Height}) {
    // The same frame without fluid: every particle's colour is the same.
    ParticleColors colors(mode, fluid_look()), plain(mode, SceneLook{});
    colors.observe(frame);
    plain.observe(frame);
    for (std::size_t i = 0; i < frame.particle_pos.size(); ++i) {
      EXPECT_EQ(colors(frame, i), plain(frame, i)) << i;
    }
  }
  ParticleColors speed(ColorBy::Speed, fluid_look());
  speed.observe(frame);
  EXPECT_EQ(speed(frame, 5), speed(frame, 0));  // as fast as the sphere: the map's top
  EXPECT_NE(speed(frame, 5), speed(frame, 9));
  ParticleColors height(ColorBy::Height, fluid_look());
  height.observe(frame);
  EXPECT_NE(height(frame, 16), height(frame, 1));  // the map along up, not water
}

// A tank of water (12 x 8 x 6 particles at the rest spacing), simulated for a moment, drawn with
// the fitted camera.
constexpr const char* kTank = R"({
  "settings": { "dt": 0.016666666666666666, "gravity": [0, -9.81, 0],
                "contact_model": "position", "particle_diameter": 0.01 },
  "materials": { "water": { "density": 1000, "friction": 0.0 },
                 "glass": { "density": 2500, "friction": 0.0 } },
  "bodies": [
    { "name": "water", "kind": "fluid", "material": "water",
      "fluid": { "type": "box", "min": [0, 0, 0], "max": [0.1204, 0.0803, 0.0602] } }
  ],
  "planes": [
    { "type": "box", "name": "tank", "min": [0, 0, 0], "max": [0.1204, 0.2, 0.0602],
      "material": "glass" }
  ]
})";

/// Sums of the pixels of a mask and how many.
struct Mean {
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  int count = 0;
  [[nodiscard]] Eigen::Vector3f value() const { return sum / static_cast<float>(count); }
};

TEST(RenderFluid, APictureOfATankIsBlueAndLighterAtTheSurface) {
  Result<Scene> scene = load_scene_text(kTank, "<tank>", ".");
  ASSERT_TRUE(scene) << scene.message();
  Result<std::unique_ptr<Device>> device = open_device("openmp");
  ASSERT_TRUE(device) << device.message();
  Result<std::unique_ptr<Simulation>> sim =
      Simulation::create(scene.value(), std::move(device).value());
  ASSERT_TRUE(sim) << sim.message();
  ASSERT_TRUE(sim.value()->step(6).is_ok());
  Result<Snapshot> taken = sim.value()->snapshot();
  ASSERT_TRUE(taken) << taken.message();
  const Snapshot& frame = taken.value();

  RenderSettings s;
  s.size = {320, 240};
  s.look = look_from_scene(scene.value());
  ASSERT_EQ(s.look.body_fluid, std::vector<std::uint8_t>{1});
  s.camera = fit_camera(frame.particle_pos, s.look.up, s.size, 35.0f, s.look.ground_height);
  s.shadows = false;
  auto draw_twice = [&](const RenderSettings& settings, const Snapshot& f) {
    FrameRenderer renderer(settings);
    const Image image = renderer.render(f);
    return std::make_pair(image, renderer.render(Snapshot{}));  // the same ground, no particles
  };
  const auto [water, background] = draw_twice(s, frame);

  // Which pixels show the surface layer (within half a diameter of the top) and which the bulk
  // (3 d or more below it): the same particles drawn in green, red and grey.
  float top = -1.0f;
  for (const shared::vec4& p : frame.particle_pos) top = std::max(top, p.y);
  const float d = 2.0f * frame.particle_pos[0].w;
  Snapshot marked = frame;
  for (std::size_t i = 0; i < frame.particle_pos.size(); ++i) {
    const float y = frame.particle_pos[i].y;
    marked.particle_body[i] = y > top - 0.5f * d ? 1 : (y < top - 3.0f * d ? 2 : 0);
  }
  RenderSettings mask_settings = s;
  mask_settings.look.body_fluid.clear();
  mask_settings.look.body_colors = {Eigen::Vector3f(0.5f, 0.5f, 0.5f),
                                    Eigen::Vector3f(0.0f, 1.0f, 0.0f),
                                    Eigen::Vector3f(1.0f, 0.0f, 0.0f)};
  const Image mask = draw_twice(mask_settings, marked).first;
  // The same picture with the fluid in its flat base colour: the light alone.
  RenderSettings flat_settings = mask_settings;
  flat_settings.look.body_colors = {water_color()};
  const Image flat = draw_twice(flat_settings, frame).first;

  Mean all, surface, bulk, flat_surface, flat_bulk;
  for (int y = 0; y < s.size.height; ++y) {
    for (int x = 0; x < s.size.width; ++x) {
      const Eigen::Vector3f c = rgb_at(water, x, y), m = rgb_at(mask, x, y);
      if (c == rgb_at(background, x, y)) continue;
      all.sum += c;
      ++all.count;
      if (m.y() > 2.0f * m.x() + 10.0f && m.y() > 2.0f * m.z() + 10.0f) {
        surface.sum += c;
        ++surface.count;
        flat_surface.sum += rgb_at(flat, x, y);
        ++flat_surface.count;
      } else if (m.x() > 2.0f * m.y() + 10.0f && m.x() > 2.0f * m.z() + 10.0f) {
        bulk.sum += c;
        ++bulk.count;
        flat_bulk.sum += rgb_at(flat, x, y);
        ++flat_bulk.count;
      }
    }
  }
  ASSERT_GT(all.count, 2000);
  ASSERT_GT(surface.count, 200);
  ASSERT_GT(bulk.count, 200);
  const Eigen::Vector3f mean = all.value();
  EXPECT_GT(mean.z(), mean.x() + 40.0f) << mean.transpose();
  EXPECT_GT(mean.z(), mean.y() + 20.0f) << mean.transpose();
  // Lighter at the surface than in the bulk, by more than the light alone makes it.
  const float ratio = surface.value().sum() / bulk.value().sum();
  const float flat_ratio = flat_surface.value().sum() / flat_bulk.value().sum();
  const auto dbl = [](float v) { return static_cast<double>(v); };
  std::printf(
      "water: mean %.0f %.0f %.0f over %d pixels; surface %.0f / bulk %.0f = %.2f, the "
      "light alone %.2f\n",
      dbl(mean.x()), dbl(mean.y()), dbl(mean.z()), all.count, dbl(surface.value().sum()),
      dbl(bulk.value().sum()), dbl(ratio), dbl(flat_ratio));
  EXPECT_GT(ratio, 1.25f * flat_ratio);
  EXPECT_TRUE(blue_dominant(bulk.value())) << bulk.value().transpose();
  EXPECT_TRUE(blue_dominant(surface.value())) << surface.value().transpose();
}

}  // namespace
}  // namespace motes::render
