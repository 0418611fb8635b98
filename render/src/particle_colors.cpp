// The colour of a particle in pictures (render.h, ParticleColors): the one rule of the headless
// renderer and of `motes view`.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "motes/render.h"
#include "render_internal.h"

namespace motes::render {

namespace {

const Eigen::Vector3f kDynamicColor(0.95f, 0.55f, 0.20f);
const Eigen::Vector3f kStaticColor(0.62f, 0.63f, 0.66f);

}  // namespace

const std::array<Eigen::Vector3f, ParticleColors::kMapStops>& ParticleColors::map_stops() {
  // viridis at 0, 1/4, 1/2, 3/4, 1.
  static const std::array<Eigen::Vector3f, kMapStops> stops = {
      Eigen::Vector3f(0.267f, 0.005f, 0.329f), Eigen::Vector3f(0.229f, 0.322f, 0.546f),
      Eigen::Vector3f(0.128f, 0.567f, 0.551f), Eigen::Vector3f(0.369f, 0.789f, 0.383f),
      Eigen::Vector3f(0.993f, 0.906f, 0.144f)};
  return stops;
}

ParticleColors::ParticleColors(ColorBy color_by, SceneLook look)
    : color_by_(color_by), look_(std::move(look)) {
  look_.up = look_.up.norm() > 0.0f ? look_.up.normalized() : Eigen::Vector3f::UnitY();
}

void ParticleColors::observe(const Snapshot& frame) {
  if (!height_range_ && !frame.particle_pos.empty()) {
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (const shared::vec4& p : frame.particle_pos) {
      if (!detail::is_finite(p)) continue;
      const float h = look_.up.dot(Eigen::Vector3f(p.x, p.y, p.z));
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    }
    height_range_ = Eigen::Vector2f(lo, hi);
  }
  if (color_by_ == ColorBy::Speed) {
    float vmax2 = speed_max_ * speed_max_;
    for (const shared::vec4& v : frame.particle_vel) {
      vmax2 = std::max(vmax2, v.x * v.x + v.y * v.y + v.z * v.z);
    }
    speed_max_ = std::sqrt(vmax2);
  }
}

Eigen::Vector3f ParticleColors::operator()(const Snapshot& frame, std::size_t index) const {
  const std::uint32_t body = index < frame.particle_body.size() ? frame.particle_body[index] : 0;
  switch (color_by_) {
    case ColorBy::Body: {
      const std::vector<std::optional<Eigen::Vector3f>>& own = look_.body_colors;
      return body < own.size() && own[body] ? *own[body] : body_color(body);
    }
    case ColorBy::Kind: {
      const std::vector<std::uint8_t>& is_static = look_.body_static;
      return body < is_static.size() && is_static[body] != 0 ? kStaticColor : kDynamicColor;
    }
    case ColorBy::Speed: {
      if (index >= frame.particle_vel.size() || !(speed_max_ > 0.0f)) return detail::colormap(0);
      const shared::vec4& v = frame.particle_vel[index];
      return detail::colormap(std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z) / speed_max_);
    }
    case ColorBy::Height: {
      const shared::vec4& p = frame.particle_pos[index];
      if (!height_range_ || !((*height_range_)[1] > (*height_range_)[0])) {
        return detail::colormap(0.5f);
      }
      const float h = look_.up.dot(Eigen::Vector3f(p.x, p.y, p.z));
      return detail::colormap((h - (*height_range_)[0]) /
                              ((*height_range_)[1] - (*height_range_)[0]));
    }
  }
  return kDynamicColor;
}

}  // namespace motes::render
