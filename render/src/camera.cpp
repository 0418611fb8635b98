// Cameras: from a scene's "camera" key, fitted to the particles, and projecting points.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "motes/render.h"
#include "render_internal.h"

namespace motes::render {

namespace {

constexpr float kDegrees = std::numbers::pi_v<float> / 180.0f;
// The fitted camera looks from this far around `up` from the front (+z for y up) and this high.
constexpr float kFitAzimuthDegrees = 20.0f;
constexpr float kFitElevationDegrees = 24.0f;
// Every sphere stays inside this fraction of the picture's half-width and half-height.
constexpr float kFitFill = 0.88f;

}  // namespace

void detail::ground_axes(const Eigen::Vector3f& up, Eigen::Vector3f& x_axis,
                         Eigen::Vector3f& z_axis) {
  const Eigen::Vector3f helper =
      std::abs(up.z()) < 0.9f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
  x_axis = up.cross(helper).normalized();
  z_axis = x_axis.cross(up).normalized();
}

detail::View detail::make_view(const Camera& camera, Size size) {
  View v;
  v.eye = camera.position;
  v.forward = (camera.target - camera.position).normalized();
  v.right = v.forward.cross(camera.up).normalized();
  v.up = v.right.cross(v.forward);
  v.half_width = 0.5f * static_cast<float>(size.width);
  v.half_height = 0.5f * static_cast<float>(size.height);
  v.focal = v.half_height / std::tan(0.5f * camera.fov_degrees * kDegrees);
  return v;
}

Camera camera_from_spec(const CameraSpec& spec) {
  Camera c;
  c.position = spec.position.cast<float>();
  c.target = spec.target.cast<float>();
  c.up = spec.up.cast<float>().normalized();
  c.fov_degrees = static_cast<float>(spec.fov);
  return c;
}

Camera fit_camera(const std::vector<shared::vec4>& particles_in, const Eigen::Vector3f& up_in,
                  Size size, float fov_degrees, std::optional<float> ground_height) {
  Camera c;
  c.fov_degrees = fov_degrees;
  c.up = up_in.norm() > 0.0f ? up_in.normalized() : Eigen::Vector3f::UnitY();
  std::vector<shared::vec4> with_floor;
  const std::vector<shared::vec4>* fitted = &particles_in;
  if (ground_height && !particles_in.empty()) {
    // The box under the particles down to the ground, where falling things land.
    const detail::Bounds pb = detail::particle_bounds(particles_in);
    with_floor = particles_in;
    for (int k = 0; k < 8; ++k) {
      Eigen::Vector3f p((k & 1) != 0 ? pb.hi.x() : pb.lo.x(), (k & 2) != 0 ? pb.hi.y() : pb.lo.y(),
                        (k & 4) != 0 ? pb.hi.z() : pb.lo.z());
      p -= c.up * (c.up.dot(p) - *ground_height);
      with_floor.emplace_back(p.x(), p.y(), p.z(), pb.max_radius);
    }
    fitted = &with_floor;
  }
  const std::vector<shared::vec4>& particles = *fitted;
  const detail::Bounds b = detail::particle_bounds(particles);
  c.target = 0.5f * (b.lo + b.hi);

  Eigen::Vector3f x_axis, z_axis;
  detail::ground_axes(c.up, x_axis, z_axis);
  const float az = kFitAzimuthDegrees * kDegrees;
  const float el = kFitElevationDegrees * kDegrees;
  const Eigen::Vector3f to_eye =
      (std::cos(el) * (std::sin(az) * x_axis + std::cos(az) * z_axis) + std::sin(el) * c.up)
          .normalized();
  const Eigen::Vector3f forward = -to_eye;
  const Eigen::Vector3f right = forward.cross(c.up).normalized();
  const Eigen::Vector3f up = right.cross(forward);
  const float tan_v = kFitFill * std::tan(0.5f * fov_degrees * kDegrees);
  const float tan_h = tan_v * static_cast<float>(size.width) / static_cast<float>(size.height);

  // The eye at distance d from the target sees a sphere at (sr, su, sf) (right, up, forward of
  // the target) at depth d + sf; it fits when (|sr| + r) / (d + sf) <= tan_h, likewise up. Then
  // the target moves across the view to centre what is seen, and the distance is fitted again.
  float distance = 0.0f;
  for (int round = 0; round < 3; ++round) {
    distance = 0.0f;
    for (const shared::vec4& p : particles) {
      if (!detail::is_finite(p)) continue;
      const Eigen::Vector3f rel = Eigen::Vector3f(p.x, p.y, p.z) - c.target;
      const float sr = rel.dot(right), su = rel.dot(up), sf = rel.dot(forward);
      const float r = std::max(p.w, 0.0f);
      distance = std::max({distance, (std::abs(sr) + r) / tan_h - sf,
                           (std::abs(su) + r) / tan_v - sf, 2.0f * r - sf});
    }
    if (!(distance > 0.0f) || round == 2) break;
    const float inf = std::numeric_limits<float>::infinity();
    float xlo = inf, xhi = -inf, ylo = inf, yhi = -inf;
    for (const shared::vec4& p : particles) {
      if (!detail::is_finite(p)) continue;
      const Eigen::Vector3f rel = Eigen::Vector3f(p.x, p.y, p.z) - c.target;
      const float depth = distance + rel.dot(forward);
      const float r = std::max(p.w, 0.0f);
      xlo = std::min(xlo, (rel.dot(right) - r) / depth);
      xhi = std::max(xhi, (rel.dot(right) + r) / depth);
      ylo = std::min(ylo, (rel.dot(up) - r) / depth);
      yhi = std::max(yhi, (rel.dot(up) + r) / depth);
    }
    c.target += distance * (0.5f * (xlo + xhi) * right + 0.5f * (ylo + yhi) * up);
  }
  c.position = c.target + to_eye * distance;
  return c;
}

Projected project(const Camera& camera, Size size, const Eigen::Vector3f& point) {
  const detail::View v = detail::make_view(camera, size);
  const Eigen::Vector3f rel = point - v.eye;
  Projected p;
  p.depth = rel.dot(v.forward);
  if (p.depth > 0.0f) {
    p.x = v.half_width + v.focal * rel.dot(v.right) / p.depth;
    p.y = v.half_height - v.focal * rel.dot(v.up) / p.depth;
  }
  return p;
}

SceneLook look_from_scene(const Scene& scene) {
  SceneLook look;
  const Eigen::Vector3d g = scene.settings.gravity;
  look.up = Eigen::Vector3f::UnitY();
  if (g.norm() > 0.0) look.up = (-g.normalized()).cast<float>();
  for (const PlaneSpec& plane : scene.planes) {
    const Eigen::Vector3f n = plane.normal.cast<float>();
    if (n.dot(look.up) > 0.999f) {
      const float height = look.up.dot(plane.point.cast<float>());
      look.ground_height = look.ground_height ? std::max(*look.ground_height, height) : height;
    }
  }
  look.gravity = static_cast<float>(g.norm());
  // Body indices as in a Snapshot: the scene's bodies, then its cloths and ropes, then its fluids.
  const std::size_t count = scene.bodies.size() + scene.linked.size() + scene.fluids.size();
  look.body_static.reserve(count);
  look.body_colors.reserve(count);
  look.body_fluid.reserve(count);
  const auto own = [](const std::optional<Eigen::Vector3d>& color) {
    return color ? std::optional<Eigen::Vector3f>(color->cast<float>()) : std::nullopt;
  };
  for (const BodySpec& body : scene.bodies) {
    look.body_static.push_back(body.kind == BodyKind::Static ? 1 : 0);
    look.body_colors.push_back(own(body.color));
    look.body_fluid.push_back(0);
  }
  for (const LinkedSpec& linked : scene.linked) {
    look.body_static.push_back(0);
    look.body_colors.push_back(own(linked.color));
    look.body_fluid.push_back(0);
  }
  for (const FluidSpec& fluid : scene.fluids) {
    look.body_static.push_back(0);
    look.body_colors.push_back(own(fluid.color));
    look.body_fluid.push_back(1);
  }
  return look;
}

detail::Bounds detail::particle_bounds(const std::vector<shared::vec4>& particles) {
  Bounds b;
  if (particles.empty()) return b;
  const float inf = std::numeric_limits<float>::infinity();
  b.lo = Eigen::Vector3f::Constant(inf);
  b.hi = Eigen::Vector3f::Constant(-inf);
  double radius_sum = 0.0;
  std::size_t counted = 0;
  for (const shared::vec4& p : particles) {
    if (!is_finite(p)) continue;
    ++counted;
    const Eigen::Vector3f c(p.x, p.y, p.z);
    b.lo = b.lo.cwiseMin(c);
    b.hi = b.hi.cwiseMax(c);
    b.max_radius = std::max(b.max_radius, p.w);
    radius_sum += static_cast<double>(p.w);
  }
  if (counted == 0) return Bounds{};
  b.mean_radius = static_cast<float>(radius_sum / static_cast<double>(counted));
  return b;
}

}  // namespace motes::render
