// Private to motes_render: the camera's frame, the shadow map, colours and OpenMP pragmas.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <vector>

#include "motes/render.h"
#include "shared/common.h"

// OpenMP pragmas only where the compiler has OpenMP (otherwise -Wunknown-pragmas).
#ifdef _OPENMP
#define MOTES_OMP(directive) _Pragma(#directive)
#else
#define MOTES_OMP(directive)
#endif

namespace motes::render::detail {

/// The camera as an orthonormal frame, for rays through pixel centres.
struct View {
  Eigen::Vector3f eye;
  Eigen::Vector3f right;
  Eigen::Vector3f up;
  Eigen::Vector3f forward;
  float focal = 1.0f;  ///< pixels: half the height / tan(fov / 2)
  float half_width = 0.0f;
  float half_height = 0.0f;

  /// Direction through the point (px, py) of the picture (pixel centres at +0.5), not normalized:
  /// its part along `forward` is `focal`, so a ray parameter t is depth / focal.
  [[nodiscard]] Eigen::Vector3f ray(float px, float py) const {
    return forward * focal + right * (px - half_width) - up * (py - half_height);
  }
};

View make_view(const Camera& camera, Size size);

/// Two unit vectors across `up` (the "x" and "z" of a y-up world), for the fitted camera and the
/// ground grid.
void ground_axes(const Eigen::Vector3f& up, Eigen::Vector3f& x_axis, Eigen::Vector3f& z_axis);

/// Whether a particle's centre and radius are finite (frames read from files may hold NaN;
/// such particles are not drawn and do not move the camera).
inline bool is_finite(const shared::vec4& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.w);
}

/// The particle centres' bounds, for the ground's extent and colour ranges.
struct Bounds {
  Eigen::Vector3f lo{0.0f, 0.0f, 0.0f};
  Eigen::Vector3f hi{0.0f, 0.0f, 0.0f};
  float max_radius = 0.0f;
  float mean_radius = 0.0f;
};
Bounds particle_bounds(const std::vector<shared::vec4>& particles);

/// An orthographic depth map seen from the light: per texel, how far below the nearest surface
/// towards the light a point is (0 at the top of the scene), for soft shadows by filtering.
struct ShadowMap {
  Eigen::Vector3f light{0.0f, 1.0f, 0.0f};  ///< unit, towards the light
  Eigen::Vector3f axis_u{1.0f, 0.0f, 0.0f};
  Eigen::Vector3f axis_v{0.0f, 0.0f, 1.0f};
  float u0 = 0.0f;
  float v0 = 0.0f;
  float texel = 1.0f;  ///< world size of one texel
  float top = 0.0f;    ///< largest light . x over every particle surface
  int resolution = 0;
  std::vector<std::uint32_t> depth;  ///< float bits of top - light . x (smaller: nearer the light)

  void build(const std::vector<shared::vec4>& particles, const Eigen::Vector3f& light_dir);
  /// Fraction 0..1 of light reaching `point`: taps x taps samples spread over +-`radius` across
  /// the light, each lit unless something is nearer the light by more than `bias`.
  [[nodiscard]] float visibility(const Eigen::Vector3f& point, float radius, int taps,
                                 float bias) const;

 private:
  std::vector<Eigen::Vector4f> projected_;  // per particle: u, v, radius (texels), light . x
};

/// Nudges `value` down to `slot` when smaller, safely across threads.
void atomic_min(std::uint64_t& slot, std::uint64_t value);
void atomic_min(std::uint32_t& slot, std::uint32_t value);

/// sRGB colour (0..1) to linear light (gamma 2: squares), and back to 8 bits.
Eigen::Vector3f to_linear(const Eigen::Vector3f& srgb);
void store_srgb8(const Eigen::Vector3f& linear, std::uint8_t* out);

/// The viridis colour map at t in [0, 1] (clamped), sRGB: ParticleColors::map_stops() interpolated.
Eigen::Vector3f colormap(float t);
/// Sky behind everything, by picture row fraction (0 top, 1 bottom), linear.
Eigen::Vector3f background(float row_fraction);

/// A round "nice" grid spacing (1, 2 or 5 times a power of ten) near `approx`.
float nice_spacing(float approx);

/// The depth buffer's value where no particle was drawn.
constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

}  // namespace motes::render::detail

namespace motes::render {

struct FrameRenderer::Buffers {
  detail::View view;
  std::vector<std::uint64_t> depth_id;
  detail::ShadowMap shadow;
  Image image;
  Eigen::Vector3f light{0.0f, 1.0f, 0.0f};
  Eigen::Vector3f grid_x{1.0f, 0.0f, 0.0f};
  Eigen::Vector3f grid_z{0.0f, 0.0f, 1.0f};
  // From the first frame: where the scene is and how big, for the ground and height colours.
  bool have_extent = false;
  Eigen::Vector3f centre{0.0f, 0.0f, 0.0f};
  float radius = 1.0f;
  float particle_radius = 0.005f;
  float grid = 0.1f;
};

}  // namespace motes::render
