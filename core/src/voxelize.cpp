// Voxelization of a closed triangle mesh: cell centres of a cubic lattice, inside by ray parity.
//
// Each column of cells (fixed x, y) is a ray along +z. The crossings of the ray with the
// triangles are sorted, and a cell whose centre has an odd number of crossings below it is inside.
//
// Robustness: rays through edges and vertices are common (a column through the diagonal of a
// cube face, an apex on the lattice). The point-in-projected-triangle test is therefore exact:
// x and y of the vertices and of the columns are rounded once to a fixed-point grid of 2^28 to
// 2^29 steps over the mesh, and the 2D orientation tests are evaluated exactly in 64-bit integers.
// A column that lies exactly on a projected edge is treated as if it were moved by (eps, eps^2)
// (simulation of simplicity), so two triangles sharing an edge decide the same side for it and
// every crossing is counted once: for a closed mesh the count per column is always even. Vertical
// triangles (zero projected area) are never crossed by the moved ray and are skipped. Rounding the
// xy coordinates moves the surface by at most 4e-9 of the mesh size, far below one particle.
//
// Speed: each triangle visits only the columns inside its xy bounding box (found by binary search
// on the sorted column coordinates), so the cost is about (triangles + columns x crossings).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "motes/shapes.h"
#include "shapes_checks.h"

namespace motes {
namespace {

using shapes_detail::check_count;
using shapes_detail::check_positive;
using shapes_detail::kMaxParticles;

constexpr double kFixedPointRange = 536870912.0;  // 2^29: orientation products stay below 2^60
// Columns cost memory for their crossings (16 bytes each, at least two per column) and the
// column coordinates are arrays: limits well above any body the particle limit allows in 3D.
constexpr double kMaxColumns = 2.0e7;
constexpr double kMaxCellsPerAxis = 1.0e6;

struct FixedPoint {
  std::int64_t x = 0;
  std::int64_t y = 0;
};

/// 2 x the signed area of (a, b, p): > 0 when p is left of a -> b. Exact.
std::int64_t orient(FixedPoint a, FixedPoint b, FixedPoint p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

/// Sign of orient(a, b, p + (eps, eps^2)) for an infinitesimal eps: never 0 unless a == b.
int side(FixedPoint a, FixedPoint b, FixedPoint p) {
  const std::int64_t e = orient(a, b, p);
  if (e != 0) return e > 0 ? 1 : -1;
  // d orient / d px = -(b.y - a.y), d orient / d py = b.x - a.x.
  if (b.y != a.y) return b.y < a.y ? 1 : -1;
  if (b.x != a.x) return b.x > a.x ? 1 : -1;
  return 0;
}

struct PreparedTriangle {
  int v[3];
  std::int64_t area2;  // orient(v0, v1, v2), never 0
  FixedPoint lo, hi;   // xy bounding box
};

/// A closed mesh with its xy coordinates on the fixed-point grid.
struct PreparedMesh {
  std::string name;
  Eigen::Vector3d lo, hi;  // bounding box of the used vertices
  double origin_x = 0.0, origin_y = 0.0, scale = 1.0;
  std::vector<FixedPoint> xy;  // per vertex
  std::vector<double> z;       // per vertex
  std::vector<PreparedTriangle> triangles;
  double volume = 0.0;  // enclosed volume (absolute value of the signed volume)

  [[nodiscard]] std::int64_t fixed(double value, double origin) const {
    return std::llround((value - origin) * scale);
  }
};

Result<PreparedMesh> prepare(const TriangleMesh& mesh) {
  PreparedMesh out;
  out.name = mesh.source.empty() ? std::string("<mesh>") : mesh.source;
  const auto& name = out.name;
  if (mesh.triangles.empty()) {
    return Status::error(fmt::format("{}: the mesh has no triangles: nothing to voxelize", name));
  }
  const auto vertex_count = static_cast<int>(mesh.vertices.size());
  out.lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  out.hi = -out.lo;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const int v = mesh.triangles[t][c];
      if (v < 0 || v >= vertex_count) {
        return Status::error(
            fmt::format("{}: triangle {} uses vertex {}, but the mesh has {} vertices", name, t, v,
                        vertex_count));
      }
      const auto& p = mesh.vertices[v];
      if (!p.allFinite()) {
        return Status::error(fmt::format("{}: vertex {} has a non-finite coordinate", name, v));
      }
      out.lo = out.lo.cwiseMin(p);
      out.hi = out.hi.cwiseMax(p);
    }
  }
  const Eigen::Vector3d extent = out.hi - out.lo;
  const char* axis_names[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    if (!(extent[a] > 1e-12 * extent.maxCoeff())) {
      return Status::error(
          fmt::format("{}: the mesh is flat (its extent along {} is {} m): it encloses no volume",
                      name, axis_names[a], extent[a]));
    }
  }
  if (const auto open = count_open_edges(mesh); open > 0) {
    return Status::error(fmt::format(
        "{}: the mesh is not closed: {} open edge{} (edges not shared by exactly two "
        "triangles), so its inside is undefined; repair or close the mesh (fill its holes, e.g. "
        "in MeshLab or Blender) before voxelizing",
        name, open, open == 1 ? "" : "s"));
  }

  out.origin_x = out.lo.x();
  out.origin_y = out.lo.y();
  // A power of two, so that meshes and lattices with short binary coordinates (a cube of 1/16
  // cells) are represented exactly and points exactly on an edge stay exactly on it.
  out.scale = std::exp2(std::floor(std::log2(kFixedPointRange / std::max(extent.x(), extent.y()))));
  out.xy.resize(mesh.vertices.size());
  out.z.resize(mesh.vertices.size());
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const auto& p = mesh.vertices[v];
    out.xy[v] = {out.fixed(p.x(), out.origin_x), out.fixed(p.y(), out.origin_y)};
    out.z[v] = p.z();
  }
  const Eigen::Vector3d centre = 0.5 * (out.lo + out.hi);
  double signed_volume = 0.0;
  for (const auto& t : mesh.triangles) {
    signed_volume += (mesh.vertices[t[0]] - centre)
                         .dot((mesh.vertices[t[1]] - centre).cross(mesh.vertices[t[2]] - centre));
    PreparedTriangle p{{t[0], t[1], t[2]}, 0, {}, {}};
    const FixedPoint a = out.xy[t[0]], b = out.xy[t[1]], c = out.xy[t[2]];
    p.area2 = orient(a, b, c);
    if (p.area2 == 0) continue;  // vertical: a ray along z never crosses it
    p.lo = {std::min({a.x, b.x, c.x}), std::min({a.y, b.y, c.y})};
    p.hi = {std::max({a.x, b.x, c.x}), std::max({a.y, b.y, c.y})};
    out.triangles.push_back(p);
  }
  out.volume = std::abs(signed_volume) / 6.0;
  return out;
}

/// Cell centres first + (i, j, k) * d, i < n.x() etc., centred on the mesh bounding box.
struct Lattice {
  double d = 0.0;
  Eigen::Vector3d first;
  Eigen::Vector3d n;  // cell counts (whole numbers), as doubles for the size checks

  [[nodiscard]] double centre(int axis, std::int64_t i) const {
    return first[axis] + static_cast<double>(i) * d;
  }
};

Lattice make_lattice(const PreparedMesh& mesh, double d) {
  Lattice lattice;
  lattice.d = d;
  const Eigen::Vector3d extent = mesh.hi - mesh.lo;
  for (int a = 0; a < 3; ++a) {
    // The fewest cells that cover the extent; a mesh of exactly n cells per side gets n.
    lattice.n[a] = std::max(1.0, std::ceil(extent[a] / d * (1.0 - 1e-9)));
    lattice.first[a] = 0.5 * (mesh.lo[a] + mesh.hi[a]) - 0.5 * (lattice.n[a] - 1.0) * d;
  }
  return lattice;
}

Status check_lattice(const PreparedMesh& mesh, const Lattice& lattice) {
  const double columns = lattice.n.x() * lattice.n.y();
  if (columns > kMaxColumns || lattice.n.maxCoeff() > kMaxCellsPerAxis) {
    return Status::error(fmt::format(
        "{}: particle diameter {} m gives a lattice of {:.0f} x {:.0f} x {:.0f} cells, more "
        "than the voxelizer handles: use a larger particle diameter",
        mesh.name, lattice.d, lattice.n.x(), lattice.n.y(), lattice.n.z()));
  }
  return check_count(mesh.name, mesh.volume / (lattice.d * lattice.d * lattice.d), lattice.d);
}

/// Counts the cells inside the mesh, and appends their centres to `points` when it is not null.
Result<std::size_t> fill(const PreparedMesh& mesh, const Lattice& lattice,
                         std::vector<Eigen::Vector3f>* points) {
  const auto nx = static_cast<std::int64_t>(lattice.n.x());
  const auto ny = static_cast<std::int64_t>(lattice.n.y());
  const auto nz = static_cast<std::int64_t>(lattice.n.z());
  std::vector<std::int64_t> column_x(static_cast<std::size_t>(nx));
  std::vector<std::int64_t> column_y(static_cast<std::size_t>(ny));
  for (std::int64_t i = 0; i < nx; ++i) {
    column_x[i] = mesh.fixed(lattice.centre(0, i), mesh.origin_x);
  }
  for (std::int64_t j = 0; j < ny; ++j) {
    column_y[j] = mesh.fixed(lattice.centre(1, j), mesh.origin_y);
  }

  // (column, z) of every crossing of a column's ray with the surface.
  std::vector<std::pair<std::int64_t, double>> crossings;
  for (const auto& t : mesh.triangles) {
    const auto i0 = std::lower_bound(column_x.begin(), column_x.end(), t.lo.x) - column_x.begin();
    const auto i1 = std::upper_bound(column_x.begin(), column_x.end(), t.hi.x) - column_x.begin();
    const auto j0 = std::lower_bound(column_y.begin(), column_y.end(), t.lo.y) - column_y.begin();
    const auto j1 = std::upper_bound(column_y.begin(), column_y.end(), t.hi.y) - column_y.begin();
    const FixedPoint a = mesh.xy[t.v[0]], b = mesh.xy[t.v[1]], c = mesh.xy[t.v[2]];
    const int winding = t.area2 > 0 ? 1 : -1;
    for (auto j = j0; j < j1; ++j) {
      for (auto i = i0; i < i1; ++i) {
        const FixedPoint p{column_x[i], column_y[j]};
        if (side(b, c, p) != winding || side(c, a, p) != winding || side(a, b, p) != winding) {
          continue;
        }
        // Barycentric weights from the exact sub-areas; they sum to area2 exactly.
        const auto wa = static_cast<double>(orient(b, c, p));
        const auto wb = static_cast<double>(orient(c, a, p));
        const auto wc = static_cast<double>(orient(a, b, p));
        const double z = (wa * mesh.z[t.v[0]] + wb * mesh.z[t.v[1]] + wc * mesh.z[t.v[2]]) /
                         static_cast<double>(t.area2);
        crossings.emplace_back(i + nx * j, z);
      }
    }
  }
  std::sort(crossings.begin(), crossings.end());

  std::size_t count = 0;
  for (std::size_t s = 0; s < crossings.size();) {
    std::size_t e = s;
    while (e < crossings.size() && crossings[e].first == crossings[s].first) ++e;
    const std::int64_t column = crossings[s].first;
    if ((e - s) % 2 != 0) {
      // Impossible for a closed mesh with the exact tests above: a bug, not a user error.
      return Status::error(fmt::format(
          "{}: internal error in the voxelizer: column {} crosses the surface {} times (odd)",
          mesh.name, column, e - s));
    }
    const double x = lattice.centre(0, column % nx);
    const double y = lattice.centre(1, column / nx);
    // Cells strictly between crossings 2m and 2m+1 have an odd number of crossings below them.
    for (std::size_t m = s; m < e; m += 2) {
      const double z_in = crossings[m].second;
      const double z_out = crossings[m + 1].second;
      auto k = static_cast<std::int64_t>(std::floor((z_in - lattice.first.z()) / lattice.d));
      k = std::clamp<std::int64_t>(k, 0, nz);
      while (k > 0 && lattice.centre(2, k - 1) > z_in) --k;
      while (k < nz && lattice.centre(2, k) <= z_in) ++k;
      for (; k < nz && lattice.centre(2, k) < z_out; ++k) {
        if (++count > static_cast<std::size_t>(kMaxParticles)) {
          return check_count(mesh.name, static_cast<double>(count), lattice.d);
        }
        if (points != nullptr) {
          points->emplace_back(static_cast<float>(x), static_cast<float>(y),
                               static_cast<float>(lattice.centre(2, k)));
        }
      }
    }
    s = e;
  }
  return count;
}

Result<std::size_t> count_at(const PreparedMesh& mesh, double d) {
  const Lattice lattice = make_lattice(mesh, d);
  if (auto s = check_lattice(mesh, lattice); !s) return s;
  return fill(mesh, lattice, nullptr);
}

/// The diameter whose count is nearest to `target` (bisection on log d: the count grows like
/// 1/d^3 but not strictly monotonically, so every count seen is a candidate).
Result<double> diameter_for_count(const PreparedMesh& mesh, std::size_t target) {
  const Eigen::Vector3d extent = mesh.hi - mesh.lo;
  const double box_volume = extent.prod();
  const double volume = mesh.volume > 1e-6 * box_volume ? mesh.volume : box_volume;
  const auto goal = static_cast<double>(target);
  double best_d = 0.0;
  double best_miss = std::numeric_limits<double>::infinity();
  auto evaluate = [&](double d) -> Result<double> {
    auto count = count_at(mesh, d);
    if (!count) return count.status();
    const auto c = static_cast<double>(count.value());
    if (std::abs(c - goal) < best_miss) {
      best_miss = std::abs(c - goal);
      best_d = d;
    }
    return c;
  };

  // Bracket: d_small gives at least the target, d_large at most.
  double d = std::cbrt(volume / goal);
  auto first = evaluate(d);
  if (!first) return first.status();
  double d_small = d, d_large = d;
  double c = first.value();
  while (c < goal) {
    d_small *= 0.8;
    // A mesh that fills less than 0.1% of its bounding box encloses almost no volume (a closed
    // but collapsed surface): stop before the lattice grows without bound.
    if (box_volume / (d_small * d_small * d_small) > 1000.0 * goal) {
      return Status::error(fmt::format(
          "{}: cannot reach {} particles: only {:.0f} at diameter {} m, where the lattice over "
          "the bounding box already has 1000 times more cells (the mesh encloses almost no "
          "volume)",
          mesh.name, target, c, d_small / 0.8));
    }
    auto r = evaluate(d_small);
    if (!r) return r.status();
    c = r.value();
  }
  c = first.value();
  while (c > goal) {
    d_large *= 1.25;
    auto r = evaluate(d_large);
    if (!r) return r.status();
    c = r.value();
  }
  if (d_small == d_large) return best_d;
  // Keep count(d_small) >= target >= count(d_large) and halve the bracket in log d.
  for (int iteration = 0; iteration < 60 && best_miss > 0.0 && d_large > d_small * (1.0 + 1e-9);
       ++iteration) {
    const double middle = std::sqrt(d_small * d_large);
    auto r = evaluate(middle);
    if (!r) return r.status();
    (r.value() >= goal ? d_small : d_large) = middle;
  }
  return best_d;
}

}  // namespace

Result<ParticleSet> voxelize(const TriangleMesh& mesh, const VoxelizeOptions& options) {
  const std::string name = mesh.source.empty() ? std::string("<mesh>") : mesh.source;
  const bool has_diameter = options.diameter != 0.0;
  const bool has_count = options.target_count != 0;
  if (has_diameter == has_count) {
    return Status::error(fmt::format(
        "{}: voxelize needs exactly one of a particle diameter or a target particle count{}", name,
        has_diameter ? ", not both" : ""));
  }
  if (has_diameter) {
    if (auto s = check_positive(fmt::format("{}: particle diameter", name), options.diameter); !s) {
      return s;
    }
  } else if (static_cast<double>(options.target_count) > kMaxParticles) {
    return Status::error(
        fmt::format("{}: target particle count {} is more than the limit of {:.0f}", name,
                    options.target_count, kMaxParticles));
  }
  auto prepared = prepare(mesh);
  if (!prepared) return prepared.status();
  const PreparedMesh& ready = prepared.value();

  double d = options.diameter;
  if (has_count) {
    auto found = diameter_for_count(ready, options.target_count);
    if (!found) return found.status();
    d = found.value();
  }
  const Lattice lattice = make_lattice(ready, d);
  if (auto s = check_lattice(ready, lattice); !s) return s;
  ParticleSet set;
  set.diameter = d;
  auto count = fill(ready, lattice, &set.points);
  if (!count) return count.status();
  if (set.points.empty()) {
    return Status::error(fmt::format(
        "{}: no particle of diameter {} m fits: no cell centre lies inside the mesh (it encloses "
        "no volume, or is thinner than one particle); use a smaller particle diameter",
        name, d));
  }
  return set;
}

}  // namespace motes
