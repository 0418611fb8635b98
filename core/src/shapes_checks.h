// Private helpers shared by the shape generators and the voxelizer: parameter checks and limits.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>

#include <fmt/format.h>

#include "motes/status.h"

namespace motes::shapes_detail {

// A body's particles are indexed with 32-bit integers on every backend, and a shape this large
// would also take gigabytes; refusing it early gives a clear message instead of an allocation
// failure.
inline constexpr double kMaxParticles = 100'000'000.0;

/// Ok when `value` is finite and > 0; otherwise an error naming `what` (e.g. "sphere radius").
inline Status check_positive(const std::string& what, double value) {
  if (std::isfinite(value) && value > 0.0) return Status::ok();
  return Status::error(
      fmt::format("{} must be a positive finite number of metres, got {}", what, value));
}

/// Ok when `count` particles is within the limit; otherwise an error naming `what`.
inline Status check_count(const std::string& what, double count, double diameter) {
  if (count <= kMaxParticles) return Status::ok();
  return Status::error(fmt::format(
      "{} with particle diameter {} m would need about {:.3g} particles, more than the limit of "
      "{:.0f}: use a larger particle diameter",
      what, diameter, count, kMaxParticles));
}

}  // namespace motes::shapes_detail
