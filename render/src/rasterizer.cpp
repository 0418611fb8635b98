// FrameRenderer: sphere impostors ray-cast per pixel into a depth buffer (depth and particle id
// in one 64-bit word, so threads need no locks), then one shading pass over the pixels.
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "motes/render.h"
#include "render_internal.h"

namespace motes::render {

namespace {

using detail::View;

using detail::kEmpty;

/// Pixel span [lo, hi] (in units of focal lengths from the centre) of a sphere at (c, cz) with
/// radius r along one picture axis: the tangents from the eye in the plane of that axis.
void axis_span(float c, float cz, float r, float& lo, float& hi) {
  const float len2 = c * c + cz * cz;
  const float t = std::sqrt(std::max(len2 - r * r, 0.0f));
  // The two tangent directions: (c, cz) turned by +-asin(r / len), scaled by len.
  const float ax = c * t - cz * r, az = c * r + cz * t;
  const float bx = c * t + cz * r, bz = -c * r + cz * t;
  const float inf = std::numeric_limits<float>::infinity();
  const float a = az > 0.0f ? ax / az : (ax > 0.0f ? inf : -inf);
  const float b = bz > 0.0f ? bx / bz : (bx > 0.0f ? inf : -inf);
  lo = std::min(a, b);
  hi = std::max(a, b);
  if (az <= 0.0f || bz <= 0.0f) {
    // The sphere reaches beside the eye: it may cover the picture's whole edge on that side.
    if (c > 0.0f) hi = inf;
    if (c < 0.0f) lo = -inf;
  }
}

int clamp_pixel(float v, int max) {
  if (!(v > 0.0f)) return 0;
  if (v >= static_cast<float>(max)) return max;
  return static_cast<int>(v);
}

/// Draws every sphere into `depth_id`: per covered pixel, the nearest ray hit.
void raster_spheres(const View& view, Size size, const std::vector<shared::vec4>& particles,
                    std::vector<std::uint64_t>& depth_id) {
  const auto n = static_cast<std::int64_t>(particles.size());
  const float f = view.focal;
  MOTES_OMP(omp parallel for schedule(dynamic, 2048))
  for (std::int64_t i = 0; i < n; ++i) {
    const shared::vec4& p = particles[static_cast<std::size_t>(i)];
    const float r = p.w;
    const Eigen::Vector3f rel = Eigen::Vector3f(p.x, p.y, p.z) - view.eye;
    const float cx = rel.dot(view.right), cy = rel.dot(view.up), cz = rel.dot(view.forward);
    // Behind the eye, or the eye inside: not drawn (cameras look at scenes from outside).
    if (!(r > 0.0f) || !(cz > r * 1.0001f) || !detail::is_finite(p)) continue;
    float xlo, xhi, ylo, yhi;
    axis_span(cx, cz, r, xlo, xhi);
    axis_span(cy, cz, r, ylo, yhi);
    const int x0 = clamp_pixel(view.half_width + xlo * f, size.width - 1);
    const int x1 = clamp_pixel(view.half_width + xhi * f, size.width - 1);
    const int y0 = clamp_pixel(view.half_height - yhi * f, size.height - 1);
    const int y1 = clamp_pixel(view.half_height - ylo * f, size.height - 1);
    const float r2 = r * r;
    for (int y = y0; y <= y1; ++y) {
      const float dy = view.half_height - (static_cast<float>(y) + 0.5f);
      std::uint64_t* row =
          depth_id.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(size.width);
      for (int x = x0; x <= x1; ++x) {
        const float dx = static_cast<float>(x) + 0.5f - view.half_width;
        // Ray d = (dx, dy, f) in the view frame; the centre's distance from it is |c x d| / |d|
        // (no cancellation, unlike b^2 - ac, for spheres that are small and far away).
        const float ex = cy * f - cz * dy, ey = cz * dx - cx * f, ez = cx * dy - cy * dx;
        const float a = dx * dx + dy * dy + f * f;
        const float off2 = (ex * ex + ey * ey + ez * ez) / a;
        if (off2 > r2) continue;
        const float t = ((cx * dx + cy * dy + cz * f) - std::sqrt((r2 - off2) * a)) / a;
        if (!(t > 0.0f)) continue;
        const std::uint64_t key =
            (std::uint64_t{std::bit_cast<std::uint32_t>(t)} << 32) | static_cast<std::uint64_t>(i);
        detail::atomic_min(row[x], key);
      }
    }
  }
}

}  // namespace

FrameRenderer::FrameRenderer(RenderSettings settings)
    : settings_(std::move(settings)),
      buffers_(std::make_unique<Buffers>()),
      colors_(settings_.color_by, settings_.look) {
  Buffers& b = *buffers_;
  b.view = detail::make_view(settings_.camera, settings_.size);
  const Eigen::Vector3f up = settings_.look.up.normalized();
  // Light from above, a little left of and behind the camera: lit faces towards the viewer,
  // shadows falling right and away from it.
  b.light = (1.0f * up - 0.7f * b.view.right - 0.35f * b.view.forward).normalized();
  detail::ground_axes(up, b.grid_x, b.grid_z);
  b.image.width = settings_.size.width;
  b.image.height = settings_.size.height;
  b.image.rgb.assign(
      3 * static_cast<std::size_t>(b.image.width) * static_cast<std::size_t>(b.image.height), 0);
}

FrameRenderer::~FrameRenderer() = default;

const Image& FrameRenderer::render(const Snapshot& frame) {
  Buffers& b = *buffers_;
  const std::vector<shared::vec4>& pos = frame.particle_pos;
  const Size size = settings_.size;

  if (!b.have_extent && !pos.empty()) {
    const detail::Bounds bounds = detail::particle_bounds(pos);
    b.have_extent = true;
    b.centre = 0.5f * (bounds.lo + bounds.hi);
    b.particle_radius = std::max(bounds.mean_radius, 1e-6f);
    b.radius = std::max(0.5f * (bounds.hi - bounds.lo).norm() + bounds.max_radius,
                        10.0f * b.particle_radius);
    b.grid = detail::nice_spacing(b.radius / 5.0f);
  }
  colors_.observe(frame);

  if (settings_.shadows) {
    b.shadow.build(pos, b.light);
  } else {
    b.shadow = detail::ShadowMap{};
  }
  b.depth_id.assign(static_cast<std::size_t>(size.width) * static_cast<std::size_t>(size.height),
                    kEmpty);
  raster_spheres(b.view, size, pos, b.depth_id);

  const int height = size.height;
  MOTES_OMP(omp parallel for schedule(dynamic, 4))
  for (int y = 0; y < height; ++y) shade_row(frame, y);
  return b.image;
}

}  // namespace motes::render
