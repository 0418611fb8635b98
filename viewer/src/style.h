// Per-particle colours and the per-frame constants of the shaders (viewer/shaders/view.glsl).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "motes/viewer.h"

namespace motes::viewer {

/// A vec4 of the sphere pipeline's per-instance attributes.
using Vec4 = std::array<float, 4>;

/// The particles as the sphere pipeline reads them: centres with radii, and linear colours.
struct Instances {
  std::vector<Vec4> spheres;
  std::vector<Vec4> colors;
};

/// The colour rule as the shaders apply it (viewer/shaders/colors.glsl, std430).
struct ColorState {
  enum Mode : std::uint32_t { kAttribute = 0, kSpeed = 1, kHeight = 2 };
  std::array<Vec4, render::ParticleColors::kMapStops> stops{};
  Vec4 up{};
  Vec4 range{};
  std::uint32_t mode = kAttribute;
  std::uint32_t speed2 = 0;  ///< float bits of the largest squared speed seen
  std::uint32_t pad[2] = {0, 0};
};
static_assert(sizeof(ColorState) == 128, "ColorState: colors.glsl's layout");

/// The push constants of every viewer shader: 8 vec4 (view.glsl says what each holds).
struct ViewConstants {
  std::array<float, 32> v{};
};

/// The colours and the ground's extent for one scene, fixed by its first frame.
class Styler {
 public:
  Styler(const Style& style, const Snapshot& first_frame);
  /// Every finite particle of `frame` with its colour (speeds widen the colour range as they
  /// grow).
  void instances(const Snapshot& frame, Instances& out);
  /// The zero-copy path's colours: by speed and height the rule's data for the shaders (the
  /// speed so far); by body and kind per device particle, in `order` (scene particle of each
  /// device particle, Simulation::scene_particle_order), from `first_frame`, fluids without the
  /// per-frame water shading (ParticleColors::unshaded).
  [[nodiscard]] ColorState color_state() const;
  [[nodiscard]] std::vector<Vec4> device_colors(const Snapshot& first_frame,
                                                const std::vector<std::uint32_t>& order) const;
  [[nodiscard]] render::ColorBy color_by() const { return style_.color_by; }
  [[nodiscard]] ViewConstants constants(const render::Camera& camera, render::Size size) const;

 private:
  Style style_;
  render::ParticleColors colors_;  ///< the headless renderer's colour rule
  Eigen::Vector3f centre_{0.0f, 0.0f, 0.0f};
  float radius_ = 1.0f;
  float grid_ = 0.1f;
};

}  // namespace motes::viewer
