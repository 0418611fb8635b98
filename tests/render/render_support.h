// Helpers of the render tests: frames of a few spheres, and checks on rendered pictures.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "motes/render.h"
#include "motes/simulation.h"

namespace motes_test {

/// One sphere per entry (x, y, z, radius), each its own body in order.
inline motes::Snapshot spheres(const std::vector<Eigen::Vector4f>& list) {
  motes::Snapshot s;
  std::uint32_t body = 0;
  for (const Eigen::Vector4f& p : list) {
    s.particle_pos.emplace_back(p.x(), p.y(), p.z(), p.w());
    s.particle_vel.emplace_back(0.0f, 0.0f, 0.0f, 0.0f);
    s.particle_body.push_back(body++);
  }
  return s;
}

/// Settings for a w x h picture from a camera on +z looking at the origin, no ground, no shadows.
inline motes::render::RenderSettings plain_settings(int w, int h) {
  motes::render::RenderSettings s;
  s.size = {w, h};
  s.camera.position = Eigen::Vector3f(0.0f, 0.0f, 2.0f);
  s.camera.target = Eigen::Vector3f::Zero();
  s.camera.up = Eigen::Vector3f::UnitY();
  s.camera.fov_degrees = 40.0f;
  s.shadows = false;
  return s;
}

inline Eigen::Vector3f rgb_at(const motes::render::Image& image, int x, int y) {
  const std::uint8_t* p = image.pixel(x, y);
  return {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])};
}

/// Checks that `image` shows a shaded sphere of `color` (sRGB 0..1) centred at pixel (cx, cy)
/// with radius `r` pixels over `background` (the same picture without it): inside the disc the
/// pixels differ from the background and their mean has the colour's hue; it is shaded as a lit
/// sphere (the renderer's light comes from the upper left: that quarter of the disc is brighter
/// than the lower right one); outside 1.5 r everything equals the background.
inline ::testing::AssertionResult shows_sphere(const motes::render::Image& image,
                                               const motes::render::Image& background, float cx,
                                               float cy, float r, const Eigen::Vector3f& color) {
  if (image.width != background.width || image.height != background.height) {
    return ::testing::AssertionFailure() << "picture sizes differ";
  }
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  int inside = 0, changed = 0;
  float lit_brightness = 0.0f, dark_brightness = 0.0f;
  int lit_count = 0, dark_count = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const float dx = static_cast<float>(x) + 0.5f - cx, dy = static_cast<float>(y) + 0.5f - cy;
      const float d = std::sqrt(dx * dx + dy * dy);
      const Eigen::Vector3f c = rgb_at(image, x, y);
      const bool same = c == rgb_at(background, x, y);
      if (d < 0.8f * r) {
        ++inside;
        if (!same) ++changed;
        sum += c;
        if (dx < -0.2f * r && dy < -0.2f * r) {
          lit_brightness += c.sum();
          ++lit_count;
        } else if (dx > 0.2f * r && dy > 0.2f * r) {
          dark_brightness += c.sum();
          ++dark_count;
        }
      } else if (d > 1.5f * r && !same) {
        return ::testing::AssertionFailure()
               << "pixel (" << x << ", " << y << ") outside the sphere differs from the background";
      }
    }
  }
  if (inside == 0) return ::testing::AssertionFailure() << "the disc is outside the picture";
  if (changed < inside * 95 / 100) {
    return ::testing::AssertionFailure()
           << "only " << changed << " of " << inside << " pixels of the disc show something";
  }
  const Eigen::Vector3f mean = sum / static_cast<float>(inside);
  const float cosine = mean.normalized().dot(color.normalized());
  if (cosine < 0.97f) {
    return ::testing::AssertionFailure()
           << "mean colour (" << mean.transpose() << ") is not "
           << "the colour (" << color.transpose() << "): cosine " << cosine;
  }
  if (lit_count == 0 || dark_count == 0 ||
      !(lit_brightness / static_cast<float>(lit_count) >
        1.2f * dark_brightness / static_cast<float>(dark_count))) {
    return ::testing::AssertionFailure()
           << "not shaded as a lit sphere (the upper left is not brighter than the lower right)";
  }
  return ::testing::AssertionSuccess();
}

}  // namespace motes_test
