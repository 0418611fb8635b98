// Picking through a uniform grid of the spheres (motes/view_pick.h, docs/viewer.md).
#include <algorithm>
#include <cmath>
#include <limits>

#include "motes/view_pick.h"

namespace motes::viewer {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

/// The most cells a grid has per binned sphere (plus a few): a thin spread widens the cells.
constexpr double kCellsPerSphere = 8.0;

bool finite(const shared::vec4& s) {
  return std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.z) && std::isfinite(s.w);
}

/// Keeps the nearer of `hit` and sphere `index` at `t` (t > 0; the lower index of equal t).
void consider(PickHit& hit, std::uint32_t index, float t) {
  if (!(t > 0.0f) || t == kInf) return;
  if (!hit.hit || t < hit.t || (t == hit.t && index < hit.particle)) {
    hit.hit = true;
    hit.particle = index;
    hit.t = t;
  }
}

}  // namespace

float ray_sphere(const Eigen::Vector3f& origin, const Eigen::Vector3f& unit_dir,
                 const shared::vec4& s) {
  // The centre's distance along the ray and its offset across it, as sphere.frag: no
  // |origin - c|^2 - r^2, which loses a small sphere seen from afar to rounding.
  const Eigen::Vector3f oc = Eigen::Vector3f(s.x, s.y, s.z) - origin;
  const float along = oc.dot(unit_dir);
  const Eigen::Vector3f across = oc - along * unit_dir;
  const float off2 = across.squaredNorm();
  const float r2 = s.w * s.w;
  if (!(off2 <= r2)) return kInf;
  return along - std::sqrt(r2 - off2);
}

namespace {

/// The ray's length and direction; false when `dir` has no usable length.
bool unit(const Eigen::Vector3f& dir, float& length, Eigen::Vector3f& unit_dir) {
  length = dir.norm();
  if (!(length > 0.0f) || !std::isfinite(length)) return false;
  unit_dir = dir / length;
  return true;
}

}  // namespace

PickHit pick_every_sphere(std::span<const shared::vec4> spheres, const Pickable& pickable,
                          const Eigen::Vector3f& origin, const Eigen::Vector3f& dir) {
  PickHit hit;
  float length = 0.0f;
  Eigen::Vector3f u;
  if (!unit(dir, length, u)) return hit;
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const auto index = static_cast<std::uint32_t>(i);
    if (pickable && !pickable(index)) continue;
    ++hit.tests;
    consider(hit, index, ray_sphere(origin, u, spheres[i]));
  }
  if (hit.hit) hit.t /= length;
  return hit;
}

PickGrid::PickGrid(std::span<const shared::vec4> spheres, const Pickable& pickable) {
  std::vector<std::uint32_t> kept;
  kept.reserve(spheres.size());
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(kInf);
  Eigen::Vector3f hi = Eigen::Vector3f::Constant(-kInf);
  float largest = 0.0f;
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const auto index = static_cast<std::uint32_t>(i);
    const shared::vec4& s = spheres[i];
    if (!finite(s) || (pickable && !pickable(index))) continue;
    kept.push_back(index);
    const Eigen::Vector3f c(s.x, s.y, s.z);
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
    largest = std::max(largest, std::abs(s.w));
  }
  if (kept.empty()) return;

  // Cells at least twice the largest radius wide: a sphere's points then lie within half a cell
  // of its centre, which leaves half a cell for rounding in the walk. Wider while there would be
  // more than kCellsPerSphere cells a sphere.
  const Eigen::Vector3f extent = hi - lo;
  float cell = 2.0f * largest;
  if (!(cell > 0.0f)) cell = extent.maxCoeff() / std::cbrt(static_cast<float>(kept.size()));
  if (!(cell > 0.0f) || !std::isfinite(cell)) cell = 1.0f;
  const double budget = kCellsPerSphere * static_cast<double>(kept.size()) + 64.0;
  const auto count_cells = [&](float h) {
    double total = 1.0;
    for (int a = 0; a < 3; ++a)
      total *= std::floor(static_cast<double>(extent[a]) / static_cast<double>(h)) + 1.0;
    return total;
  };
  while (count_cells(cell) > budget && std::isfinite(cell)) cell *= 1.25f;
  lo_ = lo;
  if (std::isfinite(cell) && std::isfinite(extent.maxCoeff())) {
    cell_ = cell;
    inv_cell_ = 1.0f / cell;
    for (int a = 0; a < 3; ++a) {
      n_[a] = static_cast<int>(std::floor(extent[a] * inv_cell_)) + 1;
    }
  } else {
    // Spread over more than float's range: one cell, which pick() scans.
    n_[0] = n_[1] = n_[2] = 1;
    inv_cell_ = 0.0f;
  }

  // Counting sort by cell.
  const auto cell_of = [&](const shared::vec4& s) {
    if (inv_cell_ == 0.0f) return std::size_t{0};
    const Eigen::Vector3f c(s.x, s.y, s.z);
    std::size_t key = 0;
    for (int a = 2; a >= 0; --a) {
      const int k =
          std::clamp(static_cast<int>(std::floor((c[a] - lo_[a]) * inv_cell_)), 0, n_[a] - 1);
      key = key * static_cast<std::size_t>(n_[a]) + static_cast<std::size_t>(k);
    }
    return key;
  };
  const std::size_t total = static_cast<std::size_t>(n_[0]) * static_cast<std::size_t>(n_[1]) *
                            static_cast<std::size_t>(n_[2]);
  start_.assign(total + 1, 0);
  std::vector<std::uint32_t> key(kept.size());
  for (std::size_t k = 0; k < kept.size(); ++k) {
    key[k] = static_cast<std::uint32_t>(cell_of(spheres[kept[k]]));
    ++start_[key[k] + 1];
  }
  for (std::size_t c = 0; c < total; ++c) start_[c + 1] += start_[c];
  std::vector<std::uint32_t> next(start_.begin(), start_.end() - 1);
  spheres_.resize(kept.size());
  index_.resize(kept.size());
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const std::uint32_t at = next[key[k]]++;
    spheres_[at] = spheres[kept[k]];
    index_[at] = kept[k];
  }
}

PickHit PickGrid::pick(const Eigen::Vector3f& origin, const Eigen::Vector3f& ray) const {
  PickHit hit;
  // Distances along the unit direction until the end (as pick_every_sphere).
  float length = 0.0f;
  Eigen::Vector3f dir;
  if (spheres_.empty() || !origin.allFinite() || !unit(ray, length, dir)) return hit;

  if (n_[0] == 1 && n_[1] == 1 && n_[2] == 1) {
    // One cell: its spheres are all there is to test.
    for (std::size_t k = 0; k < spheres_.size(); ++k) {
      ++hit.tests;
      consider(hit, index_[k], ray_sphere(origin, dir, spheres_[k]));
    }
    if (hit.hit) hit.t /= length;
    return hit;
  }

  // The grid with a border of one empty cell: every point of a sphere lies inside it.
  float t0 = 0.0f;
  float t1 = kInf;
  for (int a = 0; a < 3; ++a) {
    const float box_lo = lo_[a] - cell_;
    const float box_hi = lo_[a] + static_cast<float>(n_[a] + 1) * cell_;
    if (dir[a] == 0.0f) {
      if (origin[a] < box_lo || origin[a] > box_hi) return hit;
      continue;
    }
    float ta = (box_lo - origin[a]) / dir[a];
    float tb = (box_hi - origin[a]) / dir[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (!(t0 <= t1)) return hit;

  int at[3];
  int step[3];
  float t_next[3];  // where the ray crosses into the next cell along each axis
  const auto boundary = [&](int a) {
    if (step[a] == 0) return kInf;
    const int k = at[a] + (step[a] > 0 ? 1 : 0);
    return (lo_[a] + static_cast<float>(k) * cell_ - origin[a]) / dir[a];
  };
  for (int a = 0; a < 3; ++a) {
    const float p = origin[a] + t0 * dir[a];
    at[a] = std::clamp(static_cast<int>(std::floor((p - lo_[a]) * inv_cell_)), -1, n_[a]);
    step[a] = dir[a] > 0.0f ? 1 : (dir[a] < 0.0f ? -1 : 0);
    t_next[a] = boundary(a);
  }

  // Tests the spheres of the cells [from, to] (inclusive, clipped to the grid).
  const auto test_block = [&](const int(&from)[3], const int(&to)[3]) {
    int lo[3];
    int hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(from[a], 0);
      hi[a] = std::min(to[a], n_[a] - 1);
      if (lo[a] > hi[a]) return;
    }
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        const std::size_t row = (static_cast<std::size_t>(z) * static_cast<std::size_t>(n_[1]) +
                                 static_cast<std::size_t>(y)) *
                                static_cast<std::size_t>(n_[0]);
        const std::uint32_t first = start_[row + static_cast<std::size_t>(lo[0])];
        const std::uint32_t last = start_[row + static_cast<std::size_t>(hi[0]) + 1];
        for (std::uint32_t k = first; k < last; ++k) {
          ++hit.tests;
          consider(hit, index_[k], ray_sphere(origin, dir, spheres_[k]));
        }
      }
    }
  };

  // The first cell's whole neighbourhood, then at each step the new slab of the neighbourhood.
  test_block({at[0] - 1, at[1] - 1, at[2] - 1}, {at[0] + 1, at[1] + 1, at[2] + 1});
  for (;;) {
    int a = 0;
    if (t_next[1] < t_next[a]) a = 1;
    if (t_next[2] < t_next[a]) a = 2;
    // Every sphere with a point before the cell's exit has been tested; one not yet tested
    // starts at least half a cell beyond it.
    if (hit.hit && hit.t < t_next[a]) break;
    if (step[a] == 0) break;  // all three axes: the ray stays in this cell
    at[a] += step[a];
    if (at[a] < -1 || at[a] > n_[a]) break;
    t_next[a] = boundary(a);
    int from[3] = {at[0] - 1, at[1] - 1, at[2] - 1};
    int to[3] = {at[0] + 1, at[1] + 1, at[2] + 1};
    from[a] = to[a] = at[a] + step[a];
    test_block(from, to);
  }
  if (hit.hit) hit.t /= length;
  return hit;
}

}  // namespace motes::viewer
