// Voxelization of a triangle mesh: cell centres of a cubic lattice that lie inside the mesh.
//
// Closed, manifold meshes (every edge shared by exactly two triangles): each column of cells
// (fixed x, y) is a ray along +z. The crossings of the ray with the triangles are sorted, and a
// cell whose centre has an odd number of crossings below it is inside (ray parity). When the
// triangles can be oriented consistently, each crossing also carries a sign (entering or leaving
// the solid), and a cell is inside when the signed count below it is not zero: the same cells as
// parity, except where the surface overlaps itself (two overlapping closed parts), where the count
// reaches 2 and parity would leave the overlap empty. The signed count is the exact winding number
// of a closed surface.
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
// Open or non-manifold meshes have no well-defined inside for rays (a ray through a hole sees an
// odd count). There a cell is inside when the generalized winding number w of the surface at its
// centre (winding_number.h) is above 0.5 in magnitude, and the result carries a warning. With few
// boundary edges (the rims of holes), w is exact and cheap: the signed crossings above the cell
// plus the solid angles of vertical curtains hanging below the boundary edges
// (winding::oriented_boundary), with the curtains' sides decided by the same exact predicates as
// the crossings. With many, w is summed over the triangles through a hierarchy.
//
// Speed: each triangle visits only the columns inside its xy bounding box (found by binary search
// on the sorted column coordinates), so the cost is about (triangles + columns x crossings). The
// winding number adds one curtain per boundary edge (about 40 ns each) at a few cells per run of
// cells between two crossings (fill_run bounds the rest; only in columns near the boundary,
// elsewhere the crossings decide alone), or one hierarchy query per cell (about 3 us for a few
// thousand triangles).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "motes/shapes.h"
#include "shapes_checks.h"
#include "winding_number.h"

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
// Particle positions and diameters are 32-bit floats: vertices beyond the float range cannot be
// placed, and a mesh smaller than this has particles (at most kMaxCellsPerAxis across) whose
// diameters fall below the smallest normal float (1.2e-38).
constexpr double kMaxCoordinate = 3.0e38;
constexpr double kMinExtent = 1.0e-30;
constexpr double kMaxDiameter = 3.0e38;

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
  std::int64_t area2;  // orient(v0, v1, v2), never 0: > 0 when the normal points up (+z)
  FixedPoint lo, hi;   // xy bounding box
};

/// How the cells inside are found.
enum class Rule {
  parity,   // odd number of z-ray crossings below the centre
  nonzero,  // non-zero signed count of crossings below (consistently oriented closed meshes)
  winding,  // |generalized winding number| > 0.5, summed over the triangles
  winding_boundary,  // the same, from signed crossings and the boundary's curtains
};

// Rule::winding_boundary costs about 40 ns per boundary edge and cell, a hierarchy query about 3 us
// a cell on a mesh of a few thousand triangles (measured on one core): beyond this many boundary
// edges the hierarchy is used.
constexpr std::size_t kMaxCurtains = 128;
// Rule::winding: cells whose |w| lies within this of 0.5 are evaluated again, more accurately.
constexpr double kRefineBand = 0.1;
constexpr double kRefinedAccuracy = 8.0;
// Rule::winding_boundary: below this bound on the curtains' sum, the crossings decide alone (0.5
// less a margin for rounding).
constexpr double kCurtainBound = 0.49;
constexpr double kInverseTwoPi = 0.15915494309189535;

/// A mesh ready for filling: its xy coordinates on the fixed-point grid (crossing rules) or its
/// winding-number hierarchy.
struct PreparedMesh {
  std::string name;
  Eigen::Vector3d lo, hi;  // bounding box of the used vertices
  double origin_x = 0.0, origin_y = 0.0, scale = 1.0;
  std::vector<FixedPoint> xy;  // per vertex
  std::vector<double> z;       // per vertex
  std::vector<PreparedTriangle> triangles;
  double volume = 0.0;  // enclosed volume (absolute value of the signed volume)
  Rule rule = Rule::parity;
  std::unique_ptr<winding::WindingNumber> winding;  // the Rule::winding* rules
  std::vector<winding::BoundaryEdge> boundary;      // Rule::winding_boundary
  std::vector<Eigen::Vector3d> vertices;            // Rule::winding_boundary
  std::string warning;    // why a winding rule was needed, for the user (automatic only)
  std::string condition;  // "not closed (4 open edges, ...)", ...

  [[nodiscard]] std::int64_t fixed(double value, double origin) const {
    return std::llround((value - origin) * scale);
  }
};

/// "not closed (4 open edges, ...)", "non-manifold (2 edges used by three or more triangles)", or
/// both.
std::string describe_edges(const winding::EdgeCounts& edges) {
  std::string open, non_manifold;
  if (edges.open > 0) {
    open = fmt::format("not closed ({} open edge{}, used by one triangle only)", edges.open,
                       edges.open == 1 ? "" : "s");
  }
  if (edges.non_manifold > 0) {
    non_manifold = fmt::format("non-manifold ({} edge{} used by three or more triangles)",
                               edges.non_manifold, edges.non_manifold == 1 ? "" : "s");
  }
  if (open.empty()) return non_manifold;
  if (non_manifold.empty()) return open;
  return open + " and " + non_manifold;
}

/// The mesh's name and the bounding box of the vertices its triangles use; every index in range,
/// every coordinate finite and within the range of particle positions.
Status measure(const TriangleMesh& mesh, PreparedMesh& out) {
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
      if (p.cwiseAbs().maxCoeff() > kMaxCoordinate) {
        return Status::error(fmt::format(
            "{}: vertex {} has a coordinate of {:.3g} m, outside the range of particle positions "
            "(32-bit floats: at most {:.3g} m; a scale too large?)",
            name, v, p.cwiseAbs().maxCoeff(), kMaxCoordinate));
      }
      out.lo = out.lo.cwiseMin(p);
      out.hi = out.hi.cwiseMax(p);
    }
  }
  return Status::ok();
}

/// Refuses a mesh too small for float particles, or flat (along an axis, or tilted: every vertex
/// in the plane of the largest triangle), which encloses no volume.
Status check_extent(const TriangleMesh& mesh, const PreparedMesh& out) {
  const auto& name = out.name;
  const Eigen::Vector3d extent = out.hi - out.lo;
  if (extent.maxCoeff() < kMinExtent) {
    return Status::error(fmt::format(
        "{}: the mesh is {:.3g} m across, too small for particles in 32-bit floats (at least "
        "{:.3g} m; a scale too small?)",
        name, extent.maxCoeff(), kMinExtent));
  }
  const char* axis_names[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    if (!(extent[a] > 1e-12 * extent.maxCoeff())) {
      return Status::error(
          fmt::format("{}: the mesh is flat (its extent along {} is {} m): it encloses no volume",
                      name, axis_names[a], extent[a]));
    }
  }
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                  .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    if (n.squaredNorm() > normal.squaredNorm()) {
      normal = n;
      point = mesh.vertices[t[0]];
    }
  }
  double thickness = 0.0;
  if (normal.squaredNorm() > 0.0) {
    normal.normalize();
    for (const auto& t : mesh.triangles) {
      for (int c = 0; c < 3; ++c) {
        thickness = std::max(thickness, std::abs(normal.dot(mesh.vertices[t[c]] - point)));
      }
    }
  }
  if (!(thickness > 1e-10 * extent.maxCoeff())) {
    return Status::error(fmt::format(
        "{}: the mesh is flat (all its vertices lie in one plane): it encloses no volume", name));
  }
  return Status::ok();
}

/// The automatic test's warning for a mesh that is not closed or not manifold.
std::string winding_warning(const PreparedMesh& out, const winding::Orientation& orientation) {
  std::string repaired;
  if (orientation.reversed > 0) {
    repaired = fmt::format("; {} triangle{} facing against {} neighbours {} turned first",
                           orientation.reversed, orientation.reversed == 1 ? "" : "s",
                           orientation.reversed == 1 ? "its" : "their",
                           orientation.reversed == 1 ? "was" : "were");
  }
  if (!orientation.orientable) {
    repaired +=
        "; some triangles cannot face the same way as all their neighbours (a "
        "non-orientable surface), so parts of the fill may be missing";
  }
  return fmt::format(
      "{}: the mesh is {}: it was filled where its generalized winding number is above 0.5, "
      "which bridges holes and tolerates overlaps{}; check the particles, or repair the mesh "
      "(e.g. in MeshLab or Blender) for an exact fill",
      out.name, out.condition, repaired);
}

/// The rule that finds the cells inside (out.rule, out.condition, out.warning) and the triangles
/// it uses: the mesh's, turned to face like their neighbours for the signed and winding rules.
Result<std::vector<Eigen::Vector3i>> choose_rule(const TriangleMesh& mesh, winding::InsideTest test,
                                                 PreparedMesh& out) {
  const winding::EdgeCounts edges = winding::count_edges(mesh.triangles);
  const bool closed_manifold = edges.open == 0 && edges.non_manifold == 0;
  out.condition = describe_edges(edges);
  std::vector<Eigen::Vector3i> oriented = mesh.triangles;
  winding::Orientation orientation;
  switch (test) {
    case winding::InsideTest::parity:
      if (!closed_manifold) {
        const std::size_t open = edges.open + edges.non_manifold;
        return Status::error(fmt::format(
            "{}: the mesh is not closed: {} open edge{} (edges not shared by exactly two "
            "triangles), so its inside is undefined for ray parity",
            out.name, open, open == 1 ? "" : "s"));
      }
      out.rule = Rule::parity;
      break;
    case winding::InsideTest::winding_number:
      orientation = winding::orient_consistently(mesh.vertices, oriented);
      out.rule = Rule::winding;
      break;
    case winding::InsideTest::winding_boundary:
      orientation = winding::orient_consistently(mesh.vertices, oriented);
      out.rule = Rule::winding_boundary;
      break;
    case winding::InsideTest::automatic:
      orientation = winding::orient_consistently(mesh.vertices, oriented);
      if (closed_manifold) {
        // Signed crossings need every triangle facing the same way as its neighbours; a surface
        // that cannot be oriented (a Klein bottle) keeps plain parity.
        out.rule = orientation.orientable ? Rule::nonzero : Rule::parity;
      } else {
        out.rule = winding::oriented_boundary(oriented).size() <= kMaxCurtains
                       ? Rule::winding_boundary
                       : Rule::winding;
        out.warning = winding_warning(out, orientation);
      }
      break;
  }
  return oriented;
}

/// The enclosed volume, the xy coordinates on the fixed-point grid, the triangles a ray along z
/// can cross and, for the winding rules, the winding-number hierarchy.
void project(const TriangleMesh& mesh, std::vector<Eigen::Vector3i> oriented, PreparedMesh& out) {
  const Eigen::Vector3d extent = out.hi - out.lo;
  const Eigen::Vector3d centre = 0.5 * (out.lo + out.hi);
  double signed_volume = 0.0;
  for (const auto& t : oriented) {
    signed_volume += (mesh.vertices[t[0]] - centre)
                         .dot((mesh.vertices[t[1]] - centre).cross(mesh.vertices[t[2]] - centre));
  }
  out.volume = std::abs(signed_volume) / 6.0;

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
  for (const auto& t : oriented) {
    PreparedTriangle p{{t[0], t[1], t[2]}, 0, {}, {}};
    const FixedPoint a = out.xy[t[0]], b = out.xy[t[1]], c = out.xy[t[2]];
    p.area2 = orient(a, b, c);
    if (p.area2 == 0) continue;  // vertical: a ray along z never crosses it
    p.lo = {std::min({a.x, b.x, c.x}), std::min({a.y, b.y, c.y})};
    p.hi = {std::max({a.x, b.x, c.x}), std::max({a.y, b.y, c.y})};
    out.triangles.push_back(p);
  }
  if (out.rule == Rule::winding || out.rule == Rule::winding_boundary) {
    if (out.rule == Rule::winding_boundary) {
      out.boundary = winding::oriented_boundary(oriented);
      out.vertices = mesh.vertices;
    }
    out.winding = std::make_unique<winding::WindingNumber>(mesh.vertices, std::move(oriented));
  }
}

Result<PreparedMesh> prepare(const TriangleMesh& mesh, winding::InsideTest test) {
  PreparedMesh out;
  if (Status s = measure(mesh, out); !s) return s;
  if (Status s = check_extent(mesh, out); !s) return s;
  Result<std::vector<Eigen::Vector3i>> oriented = choose_rule(mesh, test, out);
  if (!oriented) return oriented.status();
  project(mesh, std::move(oriented).value(), out);
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

/// A cell count for messages: whole up to a billion, then in powers of ten (a diameter of 1e-300
/// m must not print a 300-digit number).
std::string cells(double n) {
  return n < 1e9 ? fmt::format("{:.0f}", n) : fmt::format("{:.3g}", n);
}

Status check_lattice(const PreparedMesh& mesh, const Lattice& lattice) {
  const double columns = lattice.n.x() * lattice.n.y();
  if (columns > kMaxColumns || lattice.n.maxCoeff() > kMaxCellsPerAxis) {
    return Status::error(fmt::format(
        "{}: particle diameter {} m gives a lattice of {} x {} x {} cells, more than the "
        "voxelizer handles: use a larger particle diameter",
        mesh.name, lattice.d, cells(lattice.n.x()), cells(lattice.n.y()), cells(lattice.n.z())));
  }
  return check_count(mesh.name, mesh.volume / (lattice.d * lattice.d * lattice.d), lattice.d);
}

/// Cells found inside by fill.
struct Filled {
  std::size_t count = 0;
  std::size_t overlapping = 0;  // Rule::nonzero: cells with a signed count of 2 or more
};

/// Appends the centre of cell (x, y, k) to `points` when it is not null; errors past the limit.
Status add_cell(const PreparedMesh& mesh, const Lattice& lattice, double x, double y,
                std::int64_t k, Filled& filled, std::vector<Eigen::Vector3f>* points) {
  if (++filled.count > static_cast<std::size_t>(kMaxParticles)) {
    return check_count(mesh.name, static_cast<double>(filled.count), lattice.d);
  }
  if (points != nullptr) {
    points->emplace_back(static_cast<float>(x), static_cast<float>(y),
                         static_cast<float>(lattice.centre(2, k)));
  }
  return Status::ok();
}

/// Rule::winding: one winding-number query per cell, column by column (the order of the crossing
/// rules' output).
Result<Filled> fill_winding(const PreparedMesh& mesh, const Lattice& lattice,
                            std::vector<Eigen::Vector3f>* points) {
  const auto nx = static_cast<std::int64_t>(lattice.n.x());
  const auto ny = static_cast<std::int64_t>(lattice.n.y());
  const auto nz = static_cast<std::int64_t>(lattice.n.z());
  Filled filled;
  for (std::int64_t j = 0; j < ny; ++j) {
    const double y = lattice.centre(1, j);
    for (std::int64_t i = 0; i < nx; ++i) {
      const double x = lattice.centre(0, i);
      for (std::int64_t k = 0; k < nz; ++k) {
        const Eigen::Vector3d p(x, y, lattice.centre(2, k));
        double w = (*mesh.winding)(p);
        // The hierarchy's error is below 0.05 at its default accuracy (winding_number.h); near the
        // threshold, ask again at an accuracy of about 4e-4.
        if (std::abs(std::abs(w) - 0.5) < kRefineBand) w = (*mesh.winding)(p, kRefinedAccuracy);
        if (!(std::abs(w) > 0.5)) continue;
        if (auto s = add_cell(mesh, lattice, x, y, k, filled, points); !s) return s;
      }
    }
  }
  return filled;
}

/// A crossing of a column's ray with the surface: step +1 entering the solid (the triangle faces
/// down, away from the part of the ray above it), -1 leaving it.
struct Crossing {
  std::int64_t column;
  double z;
  int step;
  bool operator<(const Crossing& o) const {
    if (column != o.column) return column < o.column;
    if (z != o.z) return z < o.z;
    return step < o.step;
  }
};

/// A boundary edge's curtain seen from one column of cells.
struct Curtain {
  double ax, ay, az, bx, by, bz;  // edge ends relative to the column's (x, y)
  int side;
  double multiplicity;
};

/// w at height z of the column: w0 (the crossings' part) plus the curtains in their order (`w`, as
/// the per-cell rule adds them), and the curtains' positive and negative terms apart.
struct CurtainSum {
  double w = 0.0, positive = 0.0, negative = 0.0;
};
CurtainSum curtain_sum(const std::vector<Curtain>& curtains, double w0, double z) {
  CurtainSum out{w0, 0.0, 0.0};
  for (const Curtain& c : curtains) {
    const double term =
        c.multiplicity * winding::curtain_fraction(Eigen::Vector3d(c.ax, c.ay, c.az - z),
                                                   Eigen::Vector3d(c.bx, c.by, c.bz - z), c.side);
    out.w += term;
    (term > 0.0 ? out.positive : out.negative) += term;
  }
  return out;
}

/// Rule::winding_boundary, cells k..last of one column, between the same two crossings (so w0,
/// the crossings' part of w, is the same for all). Each curtain's term keeps its sign along the
/// column and shrinks in magnitude as z rises (seen from higher up, the strip below the edge
/// covers a subset of the directions it covered), so over cells a..b the curtains' sum lies in
/// [positive(b) + negative(a), positive(a) + negative(b)]. Where that interval puts w on one side
/// of |w| = 0.5 (with a margin for rounding), the whole range is decided at once; otherwise it is
/// halved. A cell decided alone adds the terms in the same order as a per-cell evaluation would:
/// the same cells, with O(log n) evaluations per change of side instead of one per cell.
Status fill_run(const PreparedMesh& mesh, const Lattice& lattice,
                const std::vector<Curtain>& curtains, double w0, double x, double y,
                std::int64_t first, std::int64_t last, Filled& filled,
                std::vector<Eigen::Vector3f>* points) {
  constexpr double kMargin = 1e-9;
  auto decide = [&](auto& self, std::int64_t a, std::int64_t b, const CurtainSum& at_a,
                    const CurtainSum& at_b) -> Status {
    if (a == b) {
      if (!(std::abs(at_a.w) > 0.5)) return Status::ok();
      return add_cell(mesh, lattice, x, y, a, filled, points);
    }
    const double lo = w0 + at_b.positive + at_a.negative;
    const double hi = w0 + at_a.positive + at_b.negative;
    const bool inside = lo > 0.5 + kMargin || hi < -0.5 - kMargin;
    const bool outside = lo > -0.5 + kMargin && hi < 0.5 - kMargin;
    if (inside || outside) {
      for (std::int64_t c = a; inside && c <= b; ++c) {
        if (auto status = add_cell(mesh, lattice, x, y, c, filled, points); !status) return status;
      }
      return Status::ok();
    }
    if (b == a + 1) {
      if (auto status = self(self, a, a, at_a, at_a); !status) return status;
      return self(self, b, b, at_b, at_b);
    }
    const std::int64_t middle = a + (b - a) / 2;
    const CurtainSum at_middle = curtain_sum(curtains, w0, lattice.centre(2, middle));
    const CurtainSum after_middle = curtain_sum(curtains, w0, lattice.centre(2, middle + 1));
    if (auto status = self(self, a, middle, at_a, at_middle); !status) return status;
    return self(self, middle + 1, b, after_middle, at_b);
  };
  const CurtainSum at_first = curtain_sum(curtains, w0, lattice.centre(2, first));
  const CurtainSum at_last =
      first == last ? at_first : curtain_sum(curtains, w0, lattice.centre(2, last));
  return decide(decide, first, last, at_first, at_last);
}

/// Rule::winding_boundary: in each column, w at a cell centre = the signed crossings above it plus
/// the boundary curtains (winding::oriented_boundary), every cell of every column.
Result<Filled> fill_winding_boundary(const PreparedMesh& mesh, const Lattice& lattice,
                                     const std::vector<std::int64_t>& column_x,
                                     const std::vector<std::int64_t>& column_y,
                                     const std::vector<Crossing>& crossings,
                                     std::vector<Eigen::Vector3f>* points) {
  const auto nx = static_cast<std::int64_t>(lattice.n.x());
  const auto ny = static_cast<std::int64_t>(lattice.n.y());
  const auto nz = static_cast<std::int64_t>(lattice.n.z());
  // Columns through a boundary vertex (exactly, on the fixed-point grid) are where the curtains
  // of two edges meet; the exact predicates move such a column aside by (eps, eps^2), which the
  // curtain's floating-point formula cannot follow. These few columns sum over the triangles.
  std::vector<std::int64_t> through_vertex;
  for (const auto& e : mesh.boundary) {
    for (const int v : {e.from, e.to}) {
      const auto i = std::lower_bound(column_x.begin(), column_x.end(), mesh.xy[v].x);
      const auto j = std::lower_bound(column_y.begin(), column_y.end(), mesh.xy[v].y);
      if (i != column_x.end() && *i == mesh.xy[v].x && j != column_y.end() && *j == mesh.xy[v].y) {
        through_vertex.push_back((i - column_x.begin()) + nx * (j - column_y.begin()));
      }
    }
  }
  std::sort(through_vertex.begin(), through_vertex.end());

  std::vector<Curtain> curtains(mesh.boundary.size());
  Filled filled;
  std::size_t s = 0;
  for (std::int64_t column = 0; column < nx * ny; ++column) {
    std::size_t e = s;
    int total = 0;
    while (e < crossings.size() && crossings[e].column == column) total += crossings[e++].step;
    const std::int64_t i = column % nx;
    const std::int64_t j = column / nx;
    const double x = lattice.centre(0, i);
    const double y = lattice.centre(1, j);
    const bool exact_sum = std::binary_search(through_vertex.begin(), through_vertex.end(), column);
    const FixedPoint p{column_x[i], column_y[j]};
    // A curtain seen from the column covers at most the lune of the angle its edge subtends in xy:
    // |curtain_fraction| <= angle / (2 pi). Where the sum of these bounds is below 0.5, the
    // curtains cannot move w across 0.5 from the integer crossing count: that decides alone.
    double bound = 0.0;
    for (std::size_t c = 0; c < mesh.boundary.size(); ++c) {
      const auto& edge = mesh.boundary[c];
      const Eigen::Vector3d& a = mesh.vertices[edge.from];
      const Eigen::Vector3d& b = mesh.vertices[edge.to];
      curtains[c] = {a.x() - x,
                     a.y() - y,
                     a.z(),
                     b.x() - x,
                     b.y() - y,
                     b.z(),
                     side(mesh.xy[edge.from], mesh.xy[edge.to], p),
                     static_cast<double>(edge.multiplicity)};
      const Curtain& t = curtains[c];
      bound += std::abs(t.multiplicity) *
               std::atan2(std::abs(t.ax * t.by - t.ay * t.bx), t.ax * t.bx + t.ay * t.by);
    }
    const bool crossings_decide = bound * kInverseTwoPi < kCurtainBound;
    // The cells between two crossings share the integer part of w; walk the column run by run.
    std::size_t m = s;
    int below = 0;  // the signed crossings under the run, so those above it sum to below - total
    std::int64_t k = 0;
    while (k < nz) {
      const double z = lattice.centre(2, k);
      while (m < e && crossings[m].z < z) below += crossings[m++].step;
      if (m < e && crossings[m].z == z) {  // on the surface: outside, as for parity
        ++k;
        continue;
      }
      // The run: cells k..last, all strictly below crossing m (or the column's top).
      std::int64_t last = k;
      while (last + 1 < nz && (m == e || lattice.centre(2, last + 1) < crossings[m].z)) ++last;
      const auto w0 = static_cast<double>(below - total);
      if (exact_sum) {
        for (std::int64_t c = k; c <= last; ++c) {
          if (!(std::abs(mesh.winding->exact(Eigen::Vector3d(x, y, lattice.centre(2, c)))) > 0.5)) {
            continue;
          }
          if (auto status = add_cell(mesh, lattice, x, y, c, filled, points); !status)
            return status;
        }
      } else if (crossings_decide) {
        if (std::abs(w0) > 0.5) {
          for (std::int64_t c = k; c <= last; ++c) {
            if (auto status = add_cell(mesh, lattice, x, y, c, filled, points); !status) {
              return status;
            }
          }
        }
      } else if (auto status = fill_run(mesh, lattice, curtains, w0, x, y, k, last, filled, points);
                 !status) {
        return status;
      }
      k = last + 1;
    }
    s = e;
  }
  return filled;
}

/// Counts the cells inside the mesh, and appends their centres to `points` when it is not null.
Result<Filled> fill(const PreparedMesh& mesh, const Lattice& lattice,
                    std::vector<Eigen::Vector3f>* points) {
  if (mesh.rule == Rule::winding) return fill_winding(mesh, lattice, points);
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

  std::vector<Crossing> crossings;
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
        crossings.push_back({i + nx * j, z, -winding});
      }
    }
  }
  std::sort(crossings.begin(), crossings.end());
  if (mesh.rule == Rule::winding_boundary) {
    return fill_winding_boundary(mesh, lattice, column_x, column_y, crossings, points);
  }

  Filled filled;
  for (std::size_t s = 0; s < crossings.size();) {
    std::size_t e = s;
    int total = 0;
    while (e < crossings.size() && crossings[e].column == crossings[s].column) {
      total += crossings[e++].step;
    }
    const std::int64_t column = crossings[s].column;
    if ((e - s) % 2 != 0 || (mesh.rule == Rule::nonzero && total != 0)) {
      // Impossible for a closed mesh with the exact tests above: a bug, not a user error.
      return Status::error(fmt::format(
          "{}: internal error in the voxelizer: column {} crosses the surface {} times ({}, "
          "signed sum {})",
          mesh.name, column, e - s, (e - s) % 2 != 0 ? "odd" : "even", total));
    }
    const double x = lattice.centre(0, column % nx);
    const double y = lattice.centre(1, column / nx);
    // The cells strictly between crossings m and m + 1 have crossings s..m below them.
    int count = 0;
    for (std::size_t m = s; m + 1 < e; ++m) {
      count += crossings[m].step;
      const bool inside = mesh.rule == Rule::parity ? (m - s) % 2 == 0 : count != 0;
      if (!inside) continue;
      const double z_in = crossings[m].z;
      const double z_out = crossings[m + 1].z;
      auto k = static_cast<std::int64_t>(std::floor((z_in - lattice.first.z()) / lattice.d));
      k = std::clamp<std::int64_t>(k, 0, nz);
      while (k > 0 && lattice.centre(2, k - 1) > z_in) --k;
      while (k < nz && lattice.centre(2, k) <= z_in) ++k;
      for (; k < nz && lattice.centre(2, k) < z_out; ++k) {
        if (auto status = add_cell(mesh, lattice, x, y, k, filled, points); !status) {
          return status;
        }
        if (mesh.rule == Rule::nonzero && std::abs(count) >= 2) ++filled.overlapping;
      }
    }
    s = e;
  }
  return filled;
}

Result<std::size_t> count_at(const PreparedMesh& mesh, double d) {
  const Lattice lattice = make_lattice(mesh, d);
  if (auto s = check_lattice(mesh, lattice); !s) return s;
  auto filled = fill(mesh, lattice, nullptr);
  if (!filled) return filled.status();
  return filled->count;
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

  // Bracket: d_small gives at least the target, d_large at most. Steps of 0.8 or 1.25, or as far
  // as the cube root of count / target when that is further: the count goes like 1/d^3, and an
  // open mesh's first guess (from its signed volume) can be off by a factor of 30 in the count,
  // each step on the way a fill of a fine lattice. The ends stay the last diameters seen on
  // either side of the target.
  double d = std::cbrt(volume / goal);
  auto first = evaluate(d);
  if (!first) return first.status();
  double d_small = d, d_large = d;
  double c = first.value();
  double c_small = c, c_large = c;  // the counts at d_small and d_large
  if (c < goal) {
    // A mesh that fills less than 0.1% of its bounding box encloses almost no volume (a closed
    // but collapsed surface): stop before the lattice grows without bound.
    const double d_least = std::cbrt(box_volume / (1000.0 * goal));
    while (c < goal) {
      const double next = d_small * (c > 0.0 ? std::min(0.8, std::cbrt(c / goal)) : 0.8);
      if (d_small * 0.8 < d_least) {
        const bool open = mesh.rule == Rule::winding || mesh.rule == Rule::winding_boundary;
        return Status::error(fmt::format(
            "{}: cannot reach {} particles: only {:.0f} at diameter {} m, where the lattice over "
            "the bounding box already has 1000 times more cells (the mesh encloses almost no "
            "volume{})",
            mesh.name, target, c, d_small,
            open && !mesh.condition.empty()
                ? fmt::format(": it is {} and its winding number is above 0.5 almost nowhere",
                              mesh.condition)
                : std::string()));
      }
      d_large = d_small;
      c_large = c;
      d_small = std::max(next, d_least);
      auto r = evaluate(d_small);
      if (!r) return r.status();
      c = r.value();
      c_small = c;
    }
  } else {
    while (c > goal) {
      d_small = d_large;
      c_small = c;
      d_large *= std::max(1.25, std::cbrt(c / goal));
      auto r = evaluate(d_large);
      if (!r) return r.status();
      c = r.value();
      c_large = c;
    }
  }
  // Keep count(d_small) >= target >= count(d_large) and halve the bracket in log d. A count
  // outside the counts at the bracket's ends shows that at this scale the count no longer falls
  // as d grows: the lattice's cells slide against a surface that runs through their centres (a
  // sliver's), and the count jumps up and down; halving further only fills the lattice again
  // and again (30 fills of 390,000 cells for fuzz finding 9), so the search stops there with the
  // best count seen.
  for (int iteration = 0; iteration < 60 && best_miss > 0.0 && d_large > d_small * (1.0 + 1e-9);
       ++iteration) {
    const double middle = std::sqrt(d_small * d_large);
    auto r = evaluate(middle);
    if (!r) return r.status();
    const double count = r.value();
    if (count > c_small || count < c_large) break;
    if (count >= goal) {
      d_small = middle;
      c_small = count;
    } else {
      d_large = middle;
      c_large = count;
    }
  }
  return best_d;
}

}  // namespace

namespace winding {

Result<ParticleSet> voxelize_with(const TriangleMesh& mesh, const VoxelizeOptions& options,
                                  InsideTest test) {
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
    if (options.diameter > kMaxDiameter) {
      return Status::error(fmt::format(
          "{}: particle diameter {:.3g} m is outside the range of 32-bit floats (at most {:.3g} m)",
          name, options.diameter, kMaxDiameter));
    }
  } else if (static_cast<double>(options.target_count) > kMaxParticles) {
    return Status::error(
        fmt::format("{}: target particle count {} is more than the limit of {:.0f}", name,
                    options.target_count, kMaxParticles));
  }
  auto prepared = prepare(mesh, test);
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
  auto filled = fill(ready, lattice, &set.points);
  if (!filled) return filled.status();
  if (set.points.empty()) {
    if ((ready.rule == Rule::winding || ready.rule == Rule::winding_boundary) &&
        test == InsideTest::automatic) {
      return Status::error(fmt::format(
          "{}: the mesh is {} and encloses no volume: its generalized winding number is below 0.5 "
          "at every cell centre (particle diameter {} m), as for a single open sheet; close the "
          "mesh (a thin shape needs a smaller particle diameter)",
          name, ready.condition, d));
    }
    return Status::error(fmt::format(
        "{}: no particle of diameter {} m fits: no cell centre lies inside the mesh (it encloses "
        "no volume, or is thinner than one particle); use a smaller particle diameter",
        name, d));
  }
  if (!ready.warning.empty()) set.warnings.push_back(ready.warning);
  if (filled->overlapping > 0) {
    set.warnings.push_back(fmt::format(
        "{}: the surface overlaps itself (overlapping closed parts, or a shell inside another one "
        "facing the same way): {} of the {} particles lie inside it twice or more and were kept "
        "(non-zero winding rule), where ray parity would leave them empty",
        name, filled->overlapping, set.points.size()));
  }
  return set;
}

}  // namespace winding

Result<ParticleSet> voxelize(const TriangleMesh& mesh, const VoxelizeOptions& options) {
  return winding::voxelize_with(mesh, options, winding::InsideTest::automatic);
}

}  // namespace motes
