// The wireframes of `motes view`'s W and C keys (docs/viewer.md): the collision grid's occupied
// cells and the contacts of a state, as line segments made on the host from a snapshot.
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>

#include "motes/viewer.h"

namespace motes::viewer {

namespace {

struct Cell {
  std::int64_t x, y, z;
  bool operator==(const Cell&) const = default;
};

struct CellHash {
  std::size_t operator()(const Cell& c) const {
    const auto u = [](std::int64_t v) { return static_cast<std::uint64_t>(v); };
    return static_cast<std::size_t>(u(c.x) * 73856093u ^ u(c.y) * 19349663u ^ u(c.z) * 83492791u);
  }
};

Cell cell_of(const shared::vec4& p, double inv) {
  return {static_cast<std::int64_t>(std::floor(static_cast<double>(p.x) * inv)),
          static_cast<std::int64_t>(std::floor(static_cast<double>(p.y) * inv)),
          static_cast<std::int64_t>(std::floor(static_cast<double>(p.z) * inv))};
}

/// Two particles touch when their centres are closer than this times the sum of their radii: the
/// position solver leaves resting contacts at the sum within rounding, the force law a little
/// inside it.
constexpr float kTouching = 1.01f;

bool finite(const shared::vec4& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.w);
}

}  // namespace

Segments grid_cell_segments(const Snapshot& frame, float inv_cell_size, std::size_t max_cells) {
  Segments out;
  if (!(inv_cell_size > 0.0f)) return out;
  const double inv = static_cast<double>(inv_cell_size);
  const Eigen::Vector3f color(0.25f, 0.65f, 1.0f);
  std::unordered_set<Cell, CellHash> seen;
  for (const shared::vec4& p : frame.particle_pos) {
    if (!finite(p)) continue;
    const Cell c = cell_of(p, inv);
    if (!seen.insert(c).second) continue;
    if (seen.size() > max_cells) {
      out.truncated = true;
      break;
    }
    const Eigen::Vector3d lo(static_cast<double>(c.x) / inv, static_cast<double>(c.y) / inv,
                             static_cast<double>(c.z) / inv);
    const double h = 1.0 / inv;
    const auto corner = [&](int i) {
      return Eigen::Vector3d(lo + h * Eigen::Vector3d(i & 1, (i >> 1) & 1, (i >> 2) & 1))
          .cast<float>()
          .eval();
    };
    // The 12 edges of the cube: corners that differ in one bit.
    for (int i = 0; i < 8; ++i) {
      for (int bit = 1; bit < 8; bit <<= 1) {
        if ((i & bit) != 0) continue;
        out.ends.push_back(corner(i));
        out.ends.push_back(corner(i | bit));
        out.colors.push_back(color);
      }
    }
  }
  return out;
}

Segments contact_segments(const Snapshot& frame, std::size_t max_contacts) {
  Segments out;
  const std::size_t n = frame.particle_pos.size();
  double largest = 0.0;
  for (const shared::vec4& p : frame.particle_pos) {
    if (finite(p)) largest = std::max(largest, static_cast<double>(p.w));
  }
  if (!(largest > 0.0)) return out;
  // Cells a little larger than the largest diameter: a touching pair is in the same or
  // neighbouring cells.
  const double inv = 1.0 / (2.0 * static_cast<double>(kTouching) * largest);
  std::unordered_map<Cell, std::vector<std::uint32_t>, CellHash> cells;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (finite(frame.particle_pos[i])) cells[cell_of(frame.particle_pos[i], inv)].push_back(i);
  }
  const Eigen::Vector3f color(1.0f, 0.15f, 0.1f);
  const bool bodies = frame.particle_body.size() == n;
  for (std::uint32_t i = 0; i < n && !out.truncated; ++i) {
    const shared::vec4& a = frame.particle_pos[i];
    if (!finite(a)) continue;
    const Cell c = cell_of(a, inv);
    for (int d = 0; d < 27 && !out.truncated; ++d) {
      const auto found = cells.find({c.x + d % 3 - 1, c.y + d / 3 % 3 - 1, c.z + d / 9 - 1});
      if (found == cells.end()) continue;
      for (std::uint32_t j : found->second) {
        // Each pair once; a body's own particles are not its contacts.
        if (j <= i || (bodies && frame.particle_body[i] == frame.particle_body[j])) continue;
        const shared::vec4& b = frame.particle_pos[j];
        const Eigen::Vector3f pa(a.x, a.y, a.z), pb(b.x, b.y, b.z);
        if ((pa - pb).norm() >= kTouching * (a.w + b.w)) continue;
        if (out.colors.size() >= max_contacts) {
          out.truncated = true;
          break;
        }
        out.ends.push_back(pa);
        out.ends.push_back(pb);
        out.colors.push_back(color);
      }
    }
  }
  return out;
}

}  // namespace motes::viewer
