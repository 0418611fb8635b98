// Per-particle colours and the per-frame constants of the shaders (viewer/shaders/view.glsl).
#pragma once

#include <array>
#include <vector>

#include "motes/viewer.h"

namespace motes::viewer {

/// One particle as the sphere pipeline reads it: centre and radius, linear colour.
struct Instance {
  std::array<float, 4> sphere;
  std::array<float, 4> color;
};

/// The push constants of every viewer shader: 8 vec4 (view.glsl says what each holds).
struct ViewConstants {
  std::array<float, 32> v{};
};

/// The colours and the ground's extent for one scene, fixed by its first frame.
class Styler {
 public:
  Styler(const Style& style, const Snapshot& first_frame);
  /// Every particle of `frame` with its colour (speeds widen the colour range as they grow).
  void instances(const Snapshot& frame, std::vector<Instance>& out);
  [[nodiscard]] ViewConstants constants(const render::Camera& camera, render::Size size) const;

 private:
  Style style_;
  render::ParticleColors colors_;  ///< the headless renderer's colour rule
  Eigen::Vector3f centre_{0.0f, 0.0f, 0.0f};
  float radius_ = 1.0f;
  float grid_ = 0.1f;
};

}  // namespace motes::viewer
