// The light's depth map for soft shadows: particles drawn as hemispheres facing the light into an
// orthographic map, then looked up with percentage-closer filtering.
#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>

#include "render_internal.h"

namespace motes::render::detail {

namespace {

// The map has about this many texels across a particle's radius, within these resolutions.
constexpr float kTexelsPerRadius = 1.5f;
constexpr int kMinResolution = 256;
constexpr int kMaxResolution = 1024;
constexpr int kBands = 16;
constexpr std::uint32_t kFar = 0x7f800000u;  // +infinity: nothing towards the light

}  // namespace

void atomic_min(std::uint64_t& slot, std::uint64_t value) {
  std::atomic_ref<std::uint64_t> ref(slot);
  std::uint64_t old = ref.load(std::memory_order_relaxed);
  while (value < old && !ref.compare_exchange_weak(old, value, std::memory_order_relaxed)) {
  }
}

void atomic_min(std::uint32_t& slot, std::uint32_t value) {
  std::atomic_ref<std::uint32_t> ref(slot);
  std::uint32_t old = ref.load(std::memory_order_relaxed);
  while (value < old && !ref.compare_exchange_weak(old, value, std::memory_order_relaxed)) {
  }
}

void ShadowMap::build(const std::vector<shared::vec4>& particles,
                      const Eigen::Vector3f& light_dir) {
  light = light_dir.normalized();
  const Eigen::Vector3f helper =
      std::abs(light.y()) < 0.9f ? Eigen::Vector3f::UnitY() : Eigen::Vector3f::UnitX();
  axis_u = light.cross(helper).normalized();
  axis_v = light.cross(axis_u).normalized();

  const float inf = std::numeric_limits<float>::infinity();
  float ulo = inf, uhi = -inf, vlo = inf, vhi = -inf, rmax = 0.0f;
  top = -inf;
  for (const shared::vec4& p : particles) {
    if (!is_finite(p)) continue;
    const Eigen::Vector3f c(p.x, p.y, p.z);
    const float u = c.dot(axis_u), v = c.dot(axis_v);
    ulo = std::min(ulo, u);
    uhi = std::max(uhi, u);
    vlo = std::min(vlo, v);
    vhi = std::max(vhi, v);
    rmax = std::max(rmax, p.w);
    top = std::max(top, c.dot(light) + p.w);
  }
  if (!(top > -std::numeric_limits<float>::infinity())) {  // no finite particle
    resolution = 0;
    depth.clear();
    return;
  }
  const float margin = 2.0f * rmax;
  const float extent = std::max({uhi - ulo, vhi - vlo, 1e-6f}) + 2.0f * margin;
  const float wanted = std::ceil(extent * kTexelsPerRadius / std::max(rmax, 1e-9f));
  resolution = wanted > static_cast<float>(kMaxResolution)
                   ? kMaxResolution
                   : std::max(kMinResolution, static_cast<int>(wanted));
  depth.assign(static_cast<std::size_t>(resolution) * static_cast<std::size_t>(resolution), kFar);
  texel = extent / static_cast<float>(resolution);
  u0 = 0.5f * (ulo + uhi) - 0.5f * extent;
  v0 = 0.5f * (vlo + vhi) - 0.5f * extent;

  // Every particle as (u, v, radius) in texels and its height towards the light; then bands of
  // rows are drawn by different threads, each scanning the list, so no texel is shared.
  const auto n = static_cast<std::int64_t>(particles.size());
  projected_.resize(particles.size());
  MOTES_OMP(omp parallel for schedule(static))
  for (std::int64_t i = 0; i < n; ++i) {
    const shared::vec4& p = particles[static_cast<std::size_t>(i)];
    if (!is_finite(p)) {
      projected_[static_cast<std::size_t>(i)] = Eigen::Vector4f::Zero();  // radius 0: skipped
      continue;
    }
    const Eigen::Vector3f c(p.x, p.y, p.z);
    projected_[static_cast<std::size_t>(i)] = Eigen::Vector4f(
        (c.dot(axis_u) - u0) / texel, (c.dot(axis_v) - v0) / texel, p.w / texel, c.dot(light));
  }
  const int res = resolution;
  const int band_rows = (res + kBands - 1) / kBands;
  MOTES_OMP(omp parallel for schedule(dynamic, 1))
  for (int band = 0; band < kBands; ++band) {
    const int row_lo = band * band_rows, row_hi = std::min(res, row_lo + band_rows) - 1;
    for (const Eigen::Vector4f& q : projected_) {
      const float pu = q[0], pv = q[1], rt = q[2], h = q[3];
      if (!(rt > 0.0f)) continue;
      const int y0 = std::max(row_lo, static_cast<int>(std::floor(pv - rt)));
      const int y1 = std::min(row_hi, static_cast<int>(std::floor(pv + rt)));
      if (y0 > y1) continue;
      const int x0 = std::max(0, static_cast<int>(std::floor(pu - rt)));
      const int x1 = std::min(res - 1, static_cast<int>(std::floor(pu + rt)));
      const int cx = static_cast<int>(std::floor(pu)), cy = static_cast<int>(std::floor(pv));
      const float inv_rt2 = 1.0f / (rt * rt);
      const float radius = rt * texel;
      for (int y = y0; y <= y1; ++y) {
        const float dv = static_cast<float>(y) + 0.5f - pv;
        std::uint32_t* row =
            depth.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(res);
        for (int x = x0; x <= x1; ++x) {
          const float du = static_cast<float>(x) + 0.5f - pu;
          float rho2 = (du * du + dv * dv) * inv_rt2;
          // A particle smaller than a texel still covers the texel of its centre.
          if (rho2 > 1.0f) {
            if (x != cx || y != cy) continue;
            rho2 = 1.0f;
          }
          const float below = std::max(0.0f, top - (h + radius * std::sqrt(1.0f - rho2)));
          row[x] = std::min(row[x], std::bit_cast<std::uint32_t>(below));
        }
      }
    }
  }
}

float ShadowMap::visibility(const Eigen::Vector3f& point, float radius, int taps,
                            float bias) const {
  if (resolution == 0) return 1.0f;
  const float pu = (point.dot(axis_u) - u0) / texel, pv = (point.dot(axis_v) - v0) / texel;
  // Far outside the map (the ground towards the horizon): lit, and no int overflow below.
  const float far = 4.0f * static_cast<float>(resolution) + radius / texel;
  if (!(std::abs(pu) < far && std::abs(pv) < far)) return 1.0f;
  const float below = top - point.dot(light) - bias;
  const float step = 2.0f * radius / (texel * static_cast<float>(taps));
  const float start = -radius / texel + 0.5f * step;
  int lit = 0;
  for (int j = 0; j < taps; ++j) {
    const int y = static_cast<int>(std::floor(pv + start + step * static_cast<float>(j)));
    for (int i = 0; i < taps; ++i) {
      const int x = static_cast<int>(std::floor(pu + start + step * static_cast<float>(i)));
      if (x < 0 || y < 0 || x >= resolution || y >= resolution) {
        ++lit;
        continue;
      }
      const std::uint32_t bits =
          depth[static_cast<std::size_t>(y) * static_cast<std::size_t>(resolution) +
                static_cast<std::size_t>(x)];
      if (!(std::bit_cast<float>(bits) < below)) ++lit;
    }
  }
  return static_cast<float>(lit) / static_cast<float>(taps * taps);
}

}  // namespace motes::render::detail
