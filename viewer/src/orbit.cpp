// The mouse camera: orbit about up, pan across the view, zoom towards the target.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "motes/viewer.h"

namespace motes::viewer {

namespace {

constexpr float kRadiansPerPixel = 0.006f;
constexpr float kMaxElevation = 1.55f;  // just short of straight up or down

void ground_axes(const Eigen::Vector3f& up, Eigen::Vector3f& x_axis, Eigen::Vector3f& z_axis) {
  const Eigen::Vector3f helper =
      std::abs(up.z()) < 0.9f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
  x_axis = up.cross(helper).normalized();
  z_axis = x_axis.cross(up).normalized();
}

}  // namespace

Orbit::Orbit(const render::Camera& start)
    : start_(start), target_(start.target), fov_degrees_(start.fov_degrees) {
  up_ = start.up.norm() > 0.0f ? start.up.normalized() : Eigen::Vector3f::UnitY();
  const Eigen::Vector3f offset = start.position - start.target;
  distance_ = std::max(offset.norm(), 1e-6f);
  const Eigen::Vector3f dir = offset / distance_;
  Eigen::Vector3f x_axis, z_axis;
  ground_axes(up_, x_axis, z_axis);
  elevation_ = std::asin(std::clamp(dir.dot(up_), -1.0f, 1.0f));
  azimuth_ = std::atan2(dir.dot(x_axis), dir.dot(z_axis));
}

void Orbit::orbit(float dx, float dy) {
  if (dx == 0.0f && dy == 0.0f) return;
  moved_ = true;
  azimuth_ -= dx * kRadiansPerPixel;
  elevation_ = std::clamp(elevation_ + dy * kRadiansPerPixel, -kMaxElevation, kMaxElevation);
}

void Orbit::pan(float dx, float dy, render::Size size) {
  if (dx == 0.0f && dy == 0.0f) return;
  const render::Camera c = camera();
  moved_ = true;
  const Eigen::Vector3f forward = (c.target - c.position).normalized();
  const Eigen::Vector3f right = forward.cross(up_).normalized();
  const Eigen::Vector3f view_up = right.cross(forward);
  // World length of one pixel at the target's distance.
  const float pixel = 2.0f * distance_ *
                      std::tan(0.5f * fov_degrees_ * std::numbers::pi_v<float> / 180.0f) /
                      static_cast<float>(std::max(size.height, 1));
  target_ += (-dx * right + dy * view_up) * pixel;
}

void Orbit::zoom(float steps) {
  if (steps == 0.0f) return;
  moved_ = true;
  distance_ = std::max(distance_ * std::pow(0.9f, steps), 1e-6f);
}

render::Camera Orbit::camera() const {
  if (!moved_) return start_;
  Eigen::Vector3f x_axis, z_axis;
  ground_axes(up_, x_axis, z_axis);
  const Eigen::Vector3f to_eye =
      std::cos(elevation_) * (std::sin(azimuth_) * x_axis + std::cos(azimuth_) * z_axis) +
      std::sin(elevation_) * up_;
  render::Camera c;
  c.target = target_;
  c.position = target_ + distance_ * to_eye;
  c.up = up_;
  c.fov_degrees = fov_degrees_;
  return c;
}

}  // namespace motes::viewer
