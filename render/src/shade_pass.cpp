// The shading pass: per pixel, the nearest of particle, ground and sky, lit by one light with
// soft shadows from the shadow map and a sky/ground ambient term.
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "motes/render.h"
#include "render_internal.h"

namespace motes::render {

namespace {

const Eigen::Vector3f kGroundColor(0.86f, 0.85f, 0.82f);
const Eigen::Vector3f kGridColor(0.50f, 0.52f, 0.56f);

float smoothstep(float lo, float hi, float x) {
  const float t = std::clamp((x - lo) / (hi - lo), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

/// How much of a pixel `footprint` wide, at grid coordinate `a` (in grid cells), a grid line
/// covers; lines fade out where pixels get too coarse to draw them without shimmer.
float line_coverage(float a, float grid, float footprint) {
  const float dist = std::abs(a - std::round(a)) * grid;
  const float half_width = 0.012f * grid;
  const float cover = std::clamp((half_width - dist) / footprint + 0.5f, 0.0f, 1.0f);
  return cover * std::clamp(1.0f - (footprint / grid - 0.08f) / 0.25f, 0.0f, 1.0f);
}

}  // namespace

void FrameRenderer::shade_row(const Snapshot& frame, int y) {
  Buffers& b = *buffers_;
  const detail::View& view = b.view;
  const Size size = settings_.size;
  const Eigen::Vector3f up = settings_.look.up.normalized();
  const float eye_height = view.eye.dot(up);
  const bool has_ground =
      settings_.look.ground_height.has_value() && eye_height > *settings_.look.ground_height;
  const float ground = has_ground ? *settings_.look.ground_height : 0.0f;
  const bool shadows = settings_.shadows && b.shadow.resolution > 0;
  const float texel = b.shadow.texel;
  const Eigen::Vector3f sky =
      detail::background((static_cast<float>(y) + 0.5f) / static_cast<float>(size.height));
  const Eigen::Vector3f ground_base = detail::to_linear(kGroundColor);
  const Eigen::Vector3f grid_base = detail::to_linear(kGridColor);
  const float light_up = std::max(0.0f, up.dot(b.light));
  const float inf = std::numeric_limits<float>::infinity();
  const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(size.width);

  for (int x = 0; x < size.width; ++x) {
    const Eigen::Vector3f d = view.ray(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
    float t_ground = inf;
    if (has_ground) {
      const float dn = d.dot(up);
      if (dn < 0.0f) t_ground = (ground - eye_height) / dn;
    }
    const std::uint64_t key = b.depth_id[row + static_cast<std::size_t>(x)];
    Eigen::Vector3f color = sky;
    const float t_particle =
        key == detail::kEmpty ? inf : std::bit_cast<float>(static_cast<std::uint32_t>(key >> 32));
    if (key != detail::kEmpty && t_particle <= t_ground) {
      const auto index = static_cast<std::size_t>(key & 0xffffffffu);
      const shared::vec4& p = frame.particle_pos[index];
      const Eigen::Vector3f centre(p.x, p.y, p.z);
      const Eigen::Vector3f hit = view.eye + t_particle * d;
      const Eigen::Vector3f n = (hit - centre).normalized();
      const Eigen::Vector3f to_eye = -d.normalized();
      const float diffuse = std::max(0.0f, n.dot(b.light));
      const float lit = shadows && diffuse > 0.0f
                            ? b.shadow.visibility(hit, 0.0f, 1, 2.0f * texel + 0.5f * p.w)
                            : 1.0f;
      const float ambient = 0.16f + 0.2f * (0.5f + 0.5f * n.dot(up));
      const float rim = 0.65f + 0.35f * std::max(0.0f, n.dot(to_eye));
      const Eigen::Vector3f half = (b.light + to_eye).normalized();
      const float specular =
          diffuse > 0.0f ? 0.3f * lit * std::pow(std::max(0.0f, n.dot(half)), 48.0f) : 0.0f;
      const Eigen::Vector3f base = detail::to_linear(colors_(frame, index));
      color = base * (ambient * rim + 0.8f * diffuse * lit) + Eigen::Vector3f::Constant(specular);
    } else if (t_ground < inf) {
      const Eigen::Vector3f hit = view.eye + t_ground * d;
      const Eigen::Vector3f across = (hit - b.centre) - up * (hit - b.centre).dot(up);
      const float fade = smoothstep(2.0f * b.radius, 5.0f * b.radius, across.norm());
      if (fade < 1.0f) {
        const float dist = t_ground * d.norm();
        const float slope = std::max(0.15f, std::abs(d.normalized().dot(up)));
        const float footprint = dist / view.focal / slope;
        const float line = std::max(line_coverage(hit.dot(b.grid_x) / b.grid, b.grid, footprint),
                                    line_coverage(hit.dot(b.grid_z) / b.grid, b.grid, footprint));
        const Eigen::Vector3f base = ground_base + (grid_base - ground_base) * (0.45f * line);
        const float lit = shadows
                              ? b.shadow.visibility(hit, std::max(b.particle_radius, 1.5f * texel),
                                                    3, 1.5f * texel)
                              : 1.0f;
        const Eigen::Vector3f shaded = base * (0.42f + 0.55f * lit * light_up);
        color = shaded * (1.0f - fade) + sky * fade;
      }
    }
    detail::store_srgb8(color, b.image.rgb.data() + 3 * (row + static_cast<std::size_t>(x)));
  }
}

}  // namespace motes::render
