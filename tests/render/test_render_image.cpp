// The renderer's pictures: spheres where the projection puts them, with their colour and shading,
// the depth test, the fitted camera, the ground's shadow, and the checker itself.
#include <gtest/gtest.h>

#include <random>

#include "motes/render.h"
#include "render/render_support.h"

namespace motes::render {
namespace {

using motes_test::plain_settings;
using motes_test::rgb_at;
using motes_test::shows_sphere;
using motes_test::spheres;

/// The picture of `frame` with `settings`.
Image draw(const RenderSettings& settings, const Snapshot& frame) {
  FrameRenderer renderer(settings);
  return renderer.render(frame);
}

/// Radius in pixels of a sphere of radius r at depth z, seen at the picture's centre.
float pixel_radius(const RenderSettings& s, float r, float z) {
  const float focal = 0.5f * static_cast<float>(s.size.height) /
                      std::tan(0.5f * s.camera.fov_degrees * 3.14159265f / 180.0f);
  return focal * r / std::sqrt(z * z - r * r);
}

TEST(RenderImage, SphereAppearsWhereTheProjectionSays) {
  const RenderSettings s = plain_settings(320, 240);
  const Image empty = draw(s, Snapshot{});
  const Eigen::Vector3f at(0.25f, -0.1f, 0.0f);
  const Image image = draw(s, spheres({{at.x(), at.y(), at.z(), 0.1f}}));
  const Projected p = project(s.camera, s.size, at);
  EXPECT_GT(p.x, 200.0f);  // right of centre
  EXPECT_GT(p.y, 120.0f);  // below centre
  EXPECT_TRUE(shows_sphere(image, empty, p.x, p.y, pixel_radius(s, 0.1f, p.depth), body_color(0)));
}

TEST(RenderImage, CheckerRejectsBlankAndMisplacedPictures) {
  const RenderSettings s = plain_settings(320, 240);
  const Image empty = draw(s, Snapshot{});
  const Image image = draw(s, spheres({{0.0f, 0.0f, 0.0f, 0.1f}}));
  const float r = pixel_radius(s, 0.1f, 2.0f);
  EXPECT_TRUE(shows_sphere(image, empty, 160.0f, 120.0f, r, body_color(0)));
  // Nothing drawn: the check fails.
  EXPECT_FALSE(shows_sphere(empty, empty, 160.0f, 120.0f, r, body_color(0)));
  // An all-black picture: the disc "differs" but has no colour, and the outside differs too.
  Image black = empty;
  std::fill(black.rgb.begin(), black.rgb.end(), std::uint8_t{0});
  EXPECT_FALSE(shows_sphere(black, empty, 160.0f, 120.0f, r, body_color(0)));
  // The sphere elsewhere, or in another colour: the check fails.
  EXPECT_FALSE(shows_sphere(image, empty, 60.0f, 60.0f, r, body_color(0)));
  EXPECT_FALSE(shows_sphere(image, empty, 160.0f, 120.0f, r, Eigen::Vector3f(0.1f, 0.9f, 0.1f)));
  // A flat disc of the right colour is not a shaded sphere.
  Image flat = empty;
  for (int y = 0; y < flat.height; ++y) {
    for (int x = 0; x < flat.width; ++x) {
      const float dx = static_cast<float>(x) + 0.5f - 160.0f,
                  dy = static_cast<float>(y) + 0.5f - 120.0f;
      if (dx * dx + dy * dy < r * r) {
        const Eigen::Vector3f c = body_color(0) * 200.0f;
        std::uint8_t* px = flat.rgb.data() + 3 * (y * flat.width + x);
        for (int i = 0; i < 3; ++i) px[i] = static_cast<std::uint8_t>(c[i]);
      }
    }
  }
  EXPECT_FALSE(shows_sphere(flat, empty, 160.0f, 120.0f, r, body_color(0)));
}

TEST(RenderImage, NearerSphereHidesFartherOneWhateverTheOrder) {
  const RenderSettings s = plain_settings(200, 150);
  // Body 0 is near the camera (z = 0.5), body 1 behind it (z = -0.5) and bigger.
  const Eigen::Vector4f near_sphere(0.0f, 0.0f, 0.5f, 0.1f), far_sphere(0.0f, 0.0f, -0.5f, 0.3f);
  const Eigen::Vector3f near_color = body_color(0), far_color = body_color(1);
  for (bool near_first : {true, false}) {
    Snapshot frame =
        near_first ? spheres({near_sphere, far_sphere}) : spheres({far_sphere, near_sphere});
    if (!near_first) frame.particle_body = {1, 0};  // body ids follow the spheres
    const Image image = draw(s, frame);
    // The centre shows the near sphere's colour; a pixel beside it the far one's.
    const Eigen::Vector3f centre = rgb_at(image, 100, 75 - 5);
    const Eigen::Vector3f beside = rgb_at(image, 100 + 19, 75);
    EXPECT_GT(centre.normalized().dot(near_color.normalized()), 0.97f) << centre.transpose();
    EXPECT_LT(centre.normalized().dot(far_color.normalized()), 0.97f) << centre.transpose();
    EXPECT_GT(beside.normalized().dot(far_color.normalized()), 0.97f) << beside.transpose();
  }
}

TEST(RenderImage, FittedCameraKeepsEveryParticleInThePicture) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (const Eigen::Vector3f& extent :
       {Eigen::Vector3f(1, 1, 1), Eigen::Vector3f(3, 0.05f, 0.1f), Eigen::Vector3f(0.1f, 2, 0.1f),
        Eigen::Vector3f(0.2f, 0.2f, 4)}) {
    std::vector<shared::vec4> particles;
    for (int i = 0; i < 2000; ++i) {
      particles.emplace_back(5 + extent.x() * u(rng), 1 + extent.y() * u(rng),
                             -2 + extent.z() * u(rng), 0.02f);
    }
    for (const Size size : {Size{1280, 720}, Size{400, 800}}) {
      const Camera camera = fit_camera(particles, Eigen::Vector3f::UnitY(), size);
      float lo_x = 1e9f, hi_x = -1e9f, lo_y = 1e9f, hi_y = -1e9f;
      for (const shared::vec4& p : particles) {
        const Projected q = project(camera, size, Eigen::Vector3f(p.x, p.y, p.z));
        ASSERT_GT(q.depth, p.w);
        const float focal = 0.5f * static_cast<float>(size.height) /
                            std::tan(0.5f * camera.fov_degrees * 3.14159265f / 180.0f);
        const float r = focal * p.w / q.depth;
        lo_x = std::min(lo_x, q.x - r);
        hi_x = std::max(hi_x, q.x + r);
        lo_y = std::min(lo_y, q.y - r);
        hi_y = std::max(hi_y, q.y + r);
      }
      EXPECT_GE(lo_x, 0.0f);
      EXPECT_LE(hi_x, static_cast<float>(size.width));
      EXPECT_GE(lo_y, 0.0f);
      EXPECT_LE(hi_y, static_cast<float>(size.height));
      // ... and fills a good part of it (not fitted from far away).
      EXPECT_GT(std::max((hi_x - lo_x) / static_cast<float>(size.width),
                         (hi_y - lo_y) / static_cast<float>(size.height)),
                0.6f);
    }
  }
}

TEST(RenderImage, GroundIsDrawnAndShadowedUnderASphere) {
  RenderSettings s = plain_settings(320, 240);
  s.camera.position = Eigen::Vector3f(0.0f, 1.5f, 2.0f);
  s.look.ground_height = 0.0f;
  const Snapshot frame = spheres({{0.0f, 0.3f, 0.0f, 0.15f}});
  const Image no_ground = draw(plain_settings(320, 240), Snapshot{});
  const Image lit = draw(s, frame);
  s.shadows = true;
  const Image shadowed = draw(s, frame);
  // The bottom row sees the ground, not the sky.
  EXPECT_NE(rgb_at(lit, 160, 239), rgb_at(no_ground, 160, 239));
  // The shadow darkens some ground near the sphere, and only darkens.
  int darker = 0;
  for (int y = 0; y < 240; ++y) {
    for (int x = 0; x < 320; ++x) {
      const float a = rgb_at(lit, x, y).sum(), b = rgb_at(shadowed, x, y).sum();
      EXPECT_LE(b, a + 3.0f) << x << ", " << y;
      if (b < 0.8f * a) ++darker;
    }
  }
  EXPECT_GT(darker, 50);
}

TEST(RenderImage, ColourModesFollowKindBodyColourAndSpeed) {
  RenderSettings s = plain_settings(160, 120);
  Snapshot frame = spheres({{-0.3f, 0.0f, 0.0f, 0.1f}, {0.3f, 0.0f, 0.0f, 0.1f}});
  frame.particle_vel[1] = shared::vec4(2.0f, 0.0f, 0.0f, 0.0f);
  s.look.body_static = {1, 0};
  const Projected left = project(s.camera, s.size, {-0.3f, 0.0f, 0.0f});
  const Projected right = project(s.camera, s.size, {0.3f, 0.0f, 0.0f});
  const auto at = [](const Image& image, const Projected& p) {
    return rgb_at(image, static_cast<int>(p.x), static_cast<int>(p.y) + 3);
  };
  s.color_by = ColorBy::Kind;
  const Image kind = draw(s, frame);
  // Static: grey (channels close); dynamic: warm (red well above blue).
  const Eigen::Vector3f grey = at(kind, left), warm = at(kind, right);
  EXPECT_LT(grey.maxCoeff() - grey.minCoeff(), 20.0f) << grey.transpose();
  EXPECT_GT(warm.x(), warm.z() + 60.0f) << warm.transpose();
  s.color_by = ColorBy::Body;
  s.look.body_colors = {std::nullopt, Eigen::Vector3f(0.1f, 0.8f, 0.2f)};
  const Image own = draw(s, frame);
  // Body 0 from the palette, body 1 in the scene's own green.
  EXPECT_GT(at(own, left).normalized().dot(body_color(0).normalized()), 0.97f);
  EXPECT_GT(at(own, right).normalized().dot(Eigen::Vector3f(0.1f, 0.8f, 0.2f).normalized()), 0.97f)
      << at(own, right).transpose();
  s.color_by = ColorBy::Speed;
  const Image speed = draw(s, frame);
  // At rest: the colour map's dark purple; fastest: its yellow.
  const Eigen::Vector3f slow = at(speed, left), fast = at(speed, right);
  EXPECT_GT(slow.z(), slow.y()) << slow.transpose();
  EXPECT_GT(fast.x() + fast.y(), 2.0f * fast.z() + 100.0f) << fast.transpose();
}

TEST(RenderOptions, SizesAndColourModesParseOrSayWhy) {
  Result<Size> ok = parse_size("1280x720");
  ASSERT_TRUE(ok) << ok.message();
  EXPECT_EQ(ok->width, 1280);
  EXPECT_EQ(ok->height, 720);
  for (const char* bad :
       {"", "1280", "1280x", "x720", "-5x10", "12.5x10", "1280x720x3", "8x8", "100000x100"}) {
    Result<Size> r = parse_size(bad);
    EXPECT_FALSE(r) << bad;
    if (!r) {
      EXPECT_NE(r.message().find("invalid size"), std::string::npos) << r.message();
    }
  }
  EXPECT_TRUE(parse_color_by("speed"));
  Result<ColorBy> bad = parse_color_by("rainbow");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.message(),
            "unknown colour mode 'rainbow' (expected one of: body, speed, kind, height)");
}

}  // namespace
}  // namespace motes::render
