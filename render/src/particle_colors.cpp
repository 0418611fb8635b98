// The colour of a particle in pictures (render.h, ParticleColors): the one rule of the headless
// renderer and of `motes view`.
#include <algorithm>
#include <cmath>
#include <cstdint>
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
const Eigen::Vector3f kWaterColor(0.14f, 0.42f, 0.80f);
const Eigen::Vector3f kFoamColor(0.90f, 0.95f, 1.00f);

// The water rule (docs/rendering.md, "Colours of liquids"), in diameters d and in sqrt(g d).
constexpr float kColumnCells = 2.0f;  // a column is 2 d x 2 d across up
constexpr float kRunGap = 2.0f;       // a gap above 2 d along up starts a new run (a new surface)
constexpr float kDeepDepth = 10.0f;   // fully deep 10 d below the surface ...
constexpr float kDeepDarkening = 0.45f;  // ... at 55% of the base colour
constexpr float kTopDepth = 1.5f;        // the top layer: lighter over 1.5 d ...
constexpr float kTopLightening = 0.35f;  // ... by up to 35% of the way to white
constexpr float kSprayFrom = 2.0f;       // spray: whiter from 2 sqrt(g d) ...
constexpr float kSprayFull = 6.0f;       // ... to 6 sqrt(g d) ...
constexpr float kSprayWhitening = 0.7f;  // ... by up to 70% of the way to foam

float clamp01(float x) { return std::clamp(x, 0.0f, 1.0f); }

/// A fluid particle's colour from its base colour, its depth below the local surface (in d) and
/// its speed (in sqrt(g d)).
Eigen::Vector3f water_shade(const Eigen::Vector3f& base, float depth, float speed) {
  const float deep = clamp01(depth / kDeepDepth);
  const float top = clamp01(1.0f - depth / kTopDepth);
  const float spray = clamp01((speed - kSprayFrom) / (kSprayFull - kSprayFrom));
  Eigen::Vector3f c = base * (1.0f - kDeepDarkening * deep);
  c += kTopLightening * top * (Eigen::Vector3f::Ones() - c);
  c += kSprayWhitening * spray * (kFoamColor - c);
  return c;
}

/// A column's cell index along one axis, clamped to 32 bits.
std::uint32_t column_index(float coordinate, float cell) {
  const float k = std::floor(coordinate / cell);
  const float limit = 2.0e9f;
  return static_cast<std::uint32_t>(static_cast<std::int32_t>(std::clamp(k, -limit, limit)));
}

}  // namespace

Eigen::Vector3f water_color() { return kWaterColor; }

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
  observe_fluids(frame);
}

void ParticleColors::observe_fluids(const Snapshot& frame) {
  fluid_state_.clear();
  if (color_by_ != ColorBy::Body && color_by_ != ColorBy::Kind) return;
  if (std::none_of(look_.body_fluid.begin(), look_.body_fluid.end(),
                   [](std::uint8_t fluid) { return fluid != 0; })) {
    return;
  }
  // The fluid particles by column (2 d x 2 d across up), each column from the top down.
  struct Entry {
    std::uint64_t column;
    float height;
    std::uint32_t index;
  };
  std::vector<Entry> entries;
  float radius = 0.0f;
  for (std::size_t i = 0; i < frame.particle_pos.size(); ++i) {
    if (is_fluid(frame, i) && detail::is_finite(frame.particle_pos[i])) {
      radius = std::max(radius, frame.particle_pos[i].w);
    }
  }
  if (!(radius > 0.0f)) return;
  const float d = 2.0f * radius, cell = kColumnCells * d;
  Eigen::Vector3f axis_x, axis_z;
  detail::ground_axes(look_.up, axis_x, axis_z);
  for (std::size_t i = 0; i < frame.particle_pos.size(); ++i) {
    const shared::vec4& p = frame.particle_pos[i];
    if (!is_fluid(frame, i) || !detail::is_finite(p)) continue;
    const Eigen::Vector3f x(p.x, p.y, p.z);
    const std::uint64_t column = (std::uint64_t{column_index(axis_x.dot(x), cell)} << 32) |
                                 std::uint64_t{column_index(axis_z.dot(x), cell)};
    entries.push_back({column, look_.up.dot(x), static_cast<std::uint32_t>(i)});
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.column != b.column ? a.column < b.column
                                : (a.height != b.height ? a.height > b.height : a.index < b.index);
  });
  // Down each column: the surface is the top of the particle's run (a gap over 2 d starts one).
  const float g = look_.gravity > 0.0f ? look_.gravity : 9.81f;
  const float speed_unit = std::sqrt(g * d);
  fluid_state_.assign(frame.particle_pos.size(), Eigen::Vector2f::Zero());
  float surface = 0.0f, above = 0.0f;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const Entry& e = entries[k];
    if (k == 0 || e.column != entries[k - 1].column || above - e.height > kRunGap * d) {
      surface = e.height;
    }
    above = e.height;
    float speed = 0.0f;
    if (e.index < frame.particle_vel.size()) {
      const shared::vec4& v = frame.particle_vel[e.index];
      speed = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    }
    fluid_state_[e.index] = Eigen::Vector2f((surface - e.height) / d, speed / speed_unit);
  }
}

bool ParticleColors::is_fluid(const Snapshot& frame, std::size_t index) const {
  if (index >= frame.particle_body.size()) return false;
  const std::uint32_t body = frame.particle_body[index];
  return body < look_.body_fluid.size() && look_.body_fluid[body] != 0;
}

Eigen::Vector3f ParticleColors::operator()(const Snapshot& frame, std::size_t index) const {
  const Eigen::Vector3f color = unshaded(frame, index);
  if ((color_by_ != ColorBy::Body && color_by_ != ColorBy::Kind) || index >= fluid_state_.size() ||
      !is_fluid(frame, index)) {
    return color;
  }
  return water_shade(color, fluid_state_[index].x(), fluid_state_[index].y());
}

Eigen::Vector3f ParticleColors::unshaded(const Snapshot& frame, std::size_t index) const {
  const std::uint32_t body = index < frame.particle_body.size() ? frame.particle_body[index] : 0;
  switch (color_by_) {
    case ColorBy::Body: {
      const std::vector<std::optional<Eigen::Vector3f>>& own = look_.body_colors;
      if (body < own.size() && own[body]) return *own[body];
      return is_fluid(frame, index) ? kWaterColor : body_color(body);
    }
    case ColorBy::Kind: {
      if (is_fluid(frame, index)) return kWaterColor;
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
