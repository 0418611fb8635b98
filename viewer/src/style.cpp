// Particle colours by the headless renderer's rule (render::ParticleColors), the first frame's
// extent (as render/src/rasterizer.cpp takes it) and the shaders' constants.
#include "style.h"

#include <algorithm>
#include <cmath>
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

void Styler::instances(const Snapshot& frame, std::vector<Instance>& out) {
  colors_.observe(frame);
  out.clear();
  out.reserve(frame.particle_pos.size());
  for (std::size_t i = 0; i < frame.particle_pos.size(); ++i) {
    const shared::vec4& p = frame.particle_pos[i];
    if (!finite(p)) continue;
    const Eigen::Vector3f c = colors_(frame, i);
    const Eigen::Vector3f linear = c.cwiseProduct(c);  // gamma 2, as the headless renderer
    out.push_back({{p.x, p.y, p.z, p.w}, {linear.x(), linear.y(), linear.z(), 1.0f}});
  }
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
