// Particle colours by the headless renderer's rule (render::ParticleColors), the first frame's
// extent (as render/src/rasterizer.cpp takes it) and the shaders' constants.
#include "style.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>

namespace motes::viewer {

namespace {

bool finite(const shared::vec4& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.w);
}

/// 1, 2 or 5 times a power of ten near `approx`.
float nice_spacing(float approx) {
  if (!(approx > 0.0f) || !std::isfinite(approx)) return 1.0f;
  const float decade = std::pow(10.0f, std::floor(std::log10(approx)));
  const float m = approx / decade;
  return (m < 1.5f ? 1.0f : (m < 3.5f ? 2.0f : (m < 7.5f ? 5.0f : 10.0f))) * decade;
}

void put(ViewConstants& c, int slot, const Eigen::Vector3f& v, float w) {
  const auto i = static_cast<std::size_t>(4 * slot);
  c.v[i] = v.x();
  c.v[i + 1] = v.y();
  c.v[i + 2] = v.z();
  c.v[i + 3] = w;
}

Vec4 linear_color(const Eigen::Vector3f& srgb) {
  const Eigen::Vector3f linear = srgb.cwiseProduct(srgb);  // gamma 2, as the headless renderer
  return {linear.x(), linear.y(), linear.z(), 1.0f};
}

}  // namespace

Styler::Styler(const Style& style, const Snapshot& first_frame)
    : style_(style), colors_(style.color_by, style.look) {
  style_.look.up =
      style.look.up.norm() > 0.0f ? style.look.up.normalized() : Eigen::Vector3f::UnitY();
  colors_.observe(first_frame);  // the height colours' range
  const float inf = std::numeric_limits<float>::infinity();
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(inf), hi = Eigen::Vector3f::Constant(-inf);
  float max_radius = 0.0f;
  double radius_sum = 0.0;
  std::size_t counted = 0;
  for (const shared::vec4& p : first_frame.particle_pos) {
    if (!finite(p)) continue;
    const Eigen::Vector3f c(p.x, p.y, p.z);
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
    max_radius = std::max(max_radius, p.w);
    radius_sum += static_cast<double>(p.w);
    ++counted;
  }
  if (counted == 0) return;
  const float particle_radius =
      std::max(static_cast<float>(radius_sum / static_cast<double>(counted)), 1e-6f);
  centre_ = 0.5f * (lo + hi);
  radius_ = std::max(0.5f * (hi - lo).norm() + max_radius, 10.0f * particle_radius);
  grid_ = nice_spacing(radius_ / 5.0f);
}

void Styler::instances(const Snapshot& frame, Instances& out) {
  colors_.observe(frame);
  out.spheres.clear();
  out.colors.clear();
  out.spheres.reserve(frame.particle_pos.size());
  out.colors.reserve(frame.particle_pos.size());
  for (std::size_t i = 0; i < frame.particle_pos.size(); ++i) {
    const shared::vec4& p = frame.particle_pos[i];
    if (!finite(p)) continue;
    out.spheres.push_back({p.x, p.y, p.z, p.w});
    out.colors.push_back(linear_color(colors_(frame, i)));
  }
}

ColorState Styler::color_state() const {
  ColorState c;
  const auto& stops = render::ParticleColors::map_stops();
  for (std::size_t k = 0; k < stops.size(); ++k) {
    c.stops[k] = {stops[k].x(), stops[k].y(), stops[k].z(), 1.0f};
  }
  c.up = {colors_.up().x(), colors_.up().y(), colors_.up().z(), 0.0f};
  if (colors_.height_range()) {
    c.range = {(*colors_.height_range())[0], (*colors_.height_range())[1], 0.0f, 0.0f};
  }
  if (style_.color_by == render::ColorBy::Speed) c.mode = ColorState::kSpeed;
  if (style_.color_by == render::ColorBy::Height) c.mode = ColorState::kHeight;
  const float speed2 = colors_.speed_max() * colors_.speed_max();
  std::memcpy(&c.speed2, &speed2, sizeof(speed2));
  return c;
}

std::vector<Vec4> Styler::device_colors(const Snapshot& first_frame,
                                        const std::vector<std::uint32_t>& order) const {
  std::vector<Vec4> out(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    // Fixed for the scene: fluids in their base colour, without the per-frame water shading.
    out[i] = linear_color(colors_.unshaded(first_frame, order[i]));
  }
  return out;
}

ViewConstants Styler::constants(const render::Camera& camera, render::Size size) const {
  const Eigen::Vector3f forward = (camera.target - camera.position).normalized();
  const Eigen::Vector3f right = forward.cross(camera.up).normalized();
  const Eigen::Vector3f view_up = right.cross(forward);
  const float half_width = 0.5f * static_cast<float>(size.width);
  const float half_height = 0.5f * static_cast<float>(size.height);
  const float focal =
      half_height / std::tan(0.5f * camera.fov_degrees * std::numbers::pi_v<float> / 180.0f);
  const Eigen::Vector3f up = style_.look.up;
  const Eigen::Vector3f light = (1.0f * up - 0.7f * right - 0.35f * forward).normalized();
  const Eigen::Vector3f helper =
      std::abs(up.z()) < 0.9f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
  const Eigen::Vector3f grid_x = up.cross(helper).normalized();
  const float near = std::max(1e-3f * radius_, 1e-6f);
  const bool ground = style_.look.ground_height.has_value();
  ViewConstants c;
  put(c, 0, camera.position, focal);
  put(c, 1, right, half_width);
  put(c, 2, view_up, half_height);
  put(c, 3, forward, near);
  put(c, 4, light, grid_);
  put(c, 5, up, ground ? *style_.look.ground_height : 0.0f);
  put(c, 6, centre_, radius_);
  put(c, 7, grid_x, ground ? 1.0f : 0.0f);
  return c;
}

}  // namespace motes::viewer
