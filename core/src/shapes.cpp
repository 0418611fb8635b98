// Primitive shapes filled with equal spheres on a cubic lattice of spacing = particle diameter.
//
// Every lattice here is symmetric about the origin, so the centre of mass of each shape is the
// origin. Sizes are compared in units of the diameter with a relative slack of 1e-9, so a box of
// exactly n*d per side gives n cells even when n*d/d rounds to n - 1e-16, and lattice points
// that lie exactly on a curved surface are always kept.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>

#include <fmt/format.h>

#include "motes/shapes.h"
#include "shapes_checks.h"

namespace motes {
namespace {

using shapes_detail::check_count;
using shapes_detail::check_positive;

constexpr double kSlack = 1e-9;

/// Largest n with n <= x (up to the slack): whole cells along a length x (in diameters).
std::int64_t whole_cells(double x) {
  return static_cast<std::int64_t>(std::floor(x * (1.0 + kSlack)));
}

/// Position of cell i of n cells of spacing d, centred on 0.
double centred(std::int64_t i, std::int64_t n, double d) {
  return (static_cast<double>(i) - 0.5 * static_cast<double>(n - 1)) * d;
}

/// Error unless `size` (one of a shape's dimensions) holds at least one particle.
Status check_fits(const std::string& what, double size, double needed,
                  const std::string& needed_what, double diameter) {
  if (size * (1.0 + kSlack) >= needed) return Status::ok();
  return Status::error(
      fmt::format("{} {} m is smaller than {} {} m (particle diameter {} m): no particle fits",
                  what, size, needed_what, needed, diameter));
}

Status check_not_empty(const ParticleSet& set, const std::string& what) {
  if (!set.points.empty()) return Status::ok();
  return Status::error(
      fmt::format("{} with particle diameter {} m contains no particle", what, set.diameter));
}

/// Adds the points (i d, y, k d) of the xz lattice through the origin with i^2 + k^2 <= r^2
/// (r in diameters) at height y.
void add_disc(ParticleSet& set, double r, double y) {
  const double d = set.diameter;
  const auto reach = whole_cells(r);
  const double r2 = r * r * (1.0 + kSlack);
  for (std::int64_t i = -reach; i <= reach; ++i) {
    for (std::int64_t k = -reach; k <= reach; ++k) {
      if (static_cast<double>(i * i + k * k) > r2) continue;
      set.points.emplace_back(static_cast<float>(static_cast<double>(i) * d), static_cast<float>(y),
                              static_cast<float>(static_cast<double>(k) * d));
    }
  }
}

}  // namespace

Result<ParticleSet> box_particles(const Eigen::Vector3d& size, double diameter) {
  if (auto s = check_positive("box particle diameter", diameter); !s) return s;
  const char* axis_names[3] = {"x", "y", "z"};
  Eigen::Vector3d n;
  for (int a = 0; a < 3; ++a) {
    const std::string what = fmt::format("box size {}", axis_names[a]);
    if (auto s = check_positive(what, size[a]); !s) return s;
    if (auto s = check_fits(what, size[a], diameter, "the particle diameter", diameter); !s) {
      return s;
    }
    n[a] = std::max(1.0, std::floor(size[a] / diameter * (1.0 + kSlack)));
  }
  if (auto s = check_count("box", n.prod(), diameter); !s) return s;
  return box_lattice(n.cast<int>(), diameter);
}

Result<ParticleSet> box_lattice(const Eigen::Vector3i& counts, double diameter) {
  if (auto s = check_positive("box lattice particle diameter", diameter); !s) return s;
  const char* axis_names[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    if (counts[a] < 1) {
      return Status::error(
          fmt::format("box lattice count along {} must be a positive number of particles, got {}",
                      axis_names[a], counts[a]));
    }
  }
  const double total = static_cast<double>(counts[0]) * static_cast<double>(counts[1]) *
                       static_cast<double>(counts[2]);
  if (auto s = check_count("box lattice", total, diameter); !s) return s;
  ParticleSet set;
  set.diameter = diameter;
  set.points.reserve(static_cast<std::size_t>(total));
  // x fastest, then y, then z: a fixed order so that a body's particles are reproducible.
  for (int k = 0; k < counts[2]; ++k) {
    for (int j = 0; j < counts[1]; ++j) {
      for (int i = 0; i < counts[0]; ++i) {
        set.points.emplace_back(static_cast<float>(centred(i, counts[0], diameter)),
                                static_cast<float>(centred(j, counts[1], diameter)),
                                static_cast<float>(centred(k, counts[2], diameter)));
      }
    }
  }
  return set;
}

Result<ParticleSet> sphere_particles(double radius, double diameter) {
  if (auto s = check_positive("sphere particle diameter", diameter); !s) return s;
  if (auto s = check_positive("sphere radius", radius); !s) return s;
  if (auto s = check_fits("sphere radius", radius, 0.5 * diameter, "half the particle diameter",
                          diameter);
      !s) {
    return s;
  }
  const double r = radius / diameter;
  if (auto s = check_count("sphere", 4.0 / 3.0 * std::numbers::pi * r * r * r, diameter); !s) {
    return s;
  }
  ParticleSet set;
  set.diameter = diameter;
  // Cells centred on the lattice through the origin; a cell belongs to the sphere when its
  // centre does: (i^2 + j^2 + k^2) d^2 <= R^2.
  const auto reach = whole_cells(r);
  for (std::int64_t j = -reach; j <= reach; ++j) {
    const double jd = static_cast<double>(j);
    const double disc2 = r * r - jd * jd;
    if (disc2 < -kSlack * r * r) continue;
    add_disc(set, std::sqrt(std::max(0.0, disc2)), jd * diameter);
  }
  if (auto s = check_not_empty(set, fmt::format("sphere of radius {} m", radius)); !s) return s;
  return set;
}

Result<ParticleSet> cylinder_particles(double radius, double height, double diameter) {
  if (auto s = check_positive("cylinder particle diameter", diameter); !s) return s;
  if (auto s = check_positive("cylinder radius", radius); !s) return s;
  if (auto s = check_positive("cylinder height", height); !s) return s;
  if (auto s = check_fits("cylinder radius", radius, 0.5 * diameter, "half the particle diameter",
                          diameter);
      !s) {
    return s;
  }
  if (auto s = check_fits("cylinder height", height, diameter, "the particle diameter", diameter);
      !s) {
    return s;
  }
  const double r = radius / diameter;
  const double layer_count = std::max(1.0, std::floor(height / diameter * (1.0 + kSlack)));
  if (auto s = check_count("cylinder", std::numbers::pi * r * r * layer_count, diameter); !s) {
    return s;
  }
  const auto layers = static_cast<std::int64_t>(layer_count);
  ParticleSet set;
  set.diameter = diameter;
  // Whole layers along the axis (like a box side), discs of cell centres within the radius.
  for (std::int64_t j = 0; j < layers; ++j) add_disc(set, r, centred(j, layers, diameter));
  if (auto s = check_not_empty(set, fmt::format("cylinder of radius {} m", radius)); !s) return s;
  return set;
}

Result<ParticleSet> capsule_particles(double radius, double height, double diameter) {
  if (auto s = check_positive("capsule particle diameter", diameter); !s) return s;
  if (auto s = check_positive("capsule radius", radius); !s) return s;
  if (auto s = check_positive("capsule height", height); !s) return s;
  if (auto s = check_fits("capsule radius", radius, 0.5 * diameter, "half the particle diameter",
                          diameter);
      !s) {
    return s;
  }
  const double r = radius / diameter;
  const double half = 0.5 * height / diameter;  // half the cylinder part, in diameters
  const double volume = std::numbers::pi * r * r * (4.0 / 3.0 * r + 2.0 * half);
  if (auto s = check_count("capsule", volume, diameter); !s) return s;
  ParticleSet set;
  set.diameter = diameter;
  // Lattice through the origin; a cell belongs to the capsule when its centre lies within
  // `radius` of the axis segment |y| <= height / 2.
  const auto reach = whole_cells(half + r);
  for (std::int64_t j = -reach; j <= reach; ++j) {
    const double beyond = std::max(0.0, std::abs(static_cast<double>(j)) - half);
    const double disc2 = r * r - beyond * beyond;
    if (disc2 < -kSlack * r * r) continue;
    add_disc(set, std::sqrt(std::max(0.0, disc2)), static_cast<double>(j) * diameter);
  }
  if (auto s = check_not_empty(set, fmt::format("capsule of radius {} m", radius)); !s) return s;
  return set;
}

}  // namespace motes
