// Colours: the body palette, the colour map, the sky, and sRGB conversions.
#include <algorithm>
#include <array>
#include <cmath>

#include "motes/render.h"
#include "render_internal.h"

namespace motes::render {

namespace {

/// HSV (all 0..1) to RGB.
Eigen::Vector3f hsv(float h, float s, float v) {
  const float h6 = (h - std::floor(h)) * 6.0f;
  const int sector = static_cast<int>(h6) % 6;
  const float f = h6 - std::floor(h6);
  const float p = v * (1.0f - s), q = v * (1.0f - s * f), t = v * (1.0f - s * (1.0f - f));
  switch (sector) {
    case 0:
      return {v, t, p};
    case 1:
      return {q, v, p};
    case 2:
      return {p, v, t};
    case 3:
      return {p, q, v};
    case 4:
      return {t, p, v};
    default:
      return {v, p, q};
  }
}

}  // namespace

Eigen::Vector3f body_color(std::uint32_t index) {
  // Golden-ratio steps of hue keep neighbouring bodies apart; every third is a little darker.
  constexpr float kGolden = 0.618034f;
  const float hue = 0.02f + kGolden * static_cast<float>(index % 1024u);
  const float value = index % 3u == 2u ? 0.78f : 0.93f;
  return hsv(hue, 0.62f, value);
}

namespace detail {

Eigen::Vector3f to_linear(const Eigen::Vector3f& srgb) { return srgb.cwiseProduct(srgb); }

void store_srgb8(const Eigen::Vector3f& linear, std::uint8_t* out) {
  for (int i = 0; i < 3; ++i) {
    const float c = std::sqrt(std::clamp(linear[i], 0.0f, 1.0f));
    out[i] = static_cast<std::uint8_t>(c * 255.0f + 0.5f);
  }
}

Eigen::Vector3f colormap(float t) {
  const std::array<Eigen::Vector3f, ParticleColors::kMapStops>& stops = ParticleColors::map_stops();
  if (!(t > 0.0f)) return stops[0];
  if (t >= 1.0f) return stops[4];
  const float x = t * 4.0f;
  const auto i = static_cast<std::size_t>(x);
  const float f = x - static_cast<float>(i);
  return stops[i] * (1.0f - f) + stops[i + 1] * f;
}

Eigen::Vector3f background(float row_fraction) {
  const Eigen::Vector3f top(0.62f, 0.70f, 0.80f), bottom(0.90f, 0.92f, 0.95f);
  const float f = std::clamp(row_fraction, 0.0f, 1.0f);
  return to_linear(top * (1.0f - f) + bottom * f);
}

float nice_spacing(float approx) {
  if (!(approx > 0.0f) || !std::isfinite(approx)) return 1.0f;
  const float decade = std::pow(10.0f, std::floor(std::log10(approx)));
  const float m = approx / decade;
  const float step = m < 1.5f ? 1.0f : (m < 3.5f ? 2.0f : (m < 7.5f ? 5.0f : 10.0f));
  return step * decade;
}

}  // namespace detail

}  // namespace motes::render
