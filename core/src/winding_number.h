// The inside of meshes that are not closed: the generalized winding number (Jacobson, Kavan and
// Sorkine-Hornung, "Robust Inside-Outside Segmentation using Generalized Winding Numbers", 2013),
// summed over the triangles through a bounding-volume hierarchy whose far clusters are taken as
// dipoles (after Barill et al., "Fast Winding Numbers for Soups and Clouds", 2018), or exactly
// from ray crossings and curtains below the surface's boundary; and the mesh topology the
// voxelizer needs to choose between these and ray parity. Private to motes_core; the unit tests
// include it (they link the static libmotes).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

#include "motes/shapes.h"
#include "motes/status.h"

namespace motes::winding {

/// Signed solid angle of the triangle (a, b, c) seen from the origin, over 4 pi (Van Oosterom and
/// Strackee 1983): in [-0.5, 0.5], positive when the origin lies behind the triangle (on the side
/// opposite to its normal (b - a) x (c - a)), 0 for a degenerate triangle.
double solid_angle_fraction(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c);

/// The solid angle, over 4 pi, of the vertical half-strip hanging from the segment (a, b) down to
/// z = -infinity, seen from the origin: that of the spherical triangle (a, b, -z). `side` is the
/// sign of (a x b).z, the side of the projected segment the origin's vertical line passes (-1, 0
/// or 1), as an exact predicate of the caller decided it; it replaces the sign of the computed
/// triple product, so that the jump of the result across the strip (by 1) happens exactly where
/// the caller's ray-crossing test puts it. 0 when side is 0 (a vertical segment).
double curtain_fraction(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int side);

/// w(q) = sum over the triangles of their signed solid angle seen from q, over 4 pi. For a closed,
/// consistently oriented surface, w is the (integer) number of times the surface winds around q:
/// 1 inside, 0 outside, -1 inside an inverted one. For an open surface it varies smoothly where
/// holes are, and w = 0.5 is the natural place to put the missing surface.
class WindingNumber {
 public:
  WindingNumber(std::vector<Eigen::Vector3d> vertices, std::vector<Eigen::Vector3i> triangles);
  ~WindingNumber();
  WindingNumber(WindingNumber&&) noexcept;
  WindingNumber& operator=(WindingNumber&&) noexcept;
  WindingNumber(const WindingNumber&) = delete;
  WindingNumber& operator=(const WindingNumber&) = delete;

  /// Through the hierarchy: exact near q, dipole approximations far from it. A cluster of
  /// triangles is summed as a dipole when q is farther from its centre than `accuracy` (> 1) times
  /// its radius. Measured on the bunny (3674 triangles, with and without holes), the largest error
  /// in w is 0.05 at accuracy 2 (about 3 us a query on one core), 4e-4 at accuracy 8 (about 50 us).
  [[nodiscard]] double operator()(const Eigen::Vector3d& q, double accuracy = 2.0) const;
  /// The plain sum over every triangle (for tests and measurements).
  [[nodiscard]] double exact(const Eigen::Vector3d& q) const;

 private:
  struct Tree;
  std::unique_ptr<Tree> tree_;
};

/// Edges of a mesh by how many triangles use them (either direction).
struct EdgeCounts {
  std::size_t open = 0;          ///< used by one triangle: the rims of holes
  std::size_t non_manifold = 0;  ///< used by three or more triangles
};
EdgeCounts count_edges(const std::vector<Eigen::Vector3i>& triangles);

/// An edge where the orientation of the triangles does not cancel out: `multiplicity` = the number
/// of triangles that use it from -> to, minus those that use it to -> from (not 0).
struct BoundaryEdge {
  int from = 0;
  int to = 0;
  int multiplicity = 0;
};
/// The oriented boundary of the surface (the rims of its holes, a face duplicated with the same
/// orientation, ...): empty for a closed, consistently oriented surface.
///
/// With it, the winding number needs no sum over the triangles. Hang a curtain (a vertical strip
/// to z = -infinity) below each boundary edge: the surface and its curtains form a closed surface,
/// whose winding number at q is the signed count of its crossings with the ray from q to z = +inf
/// (the curtains are vertical: the ray never crosses them). So
///   w(q) = sum over the crossings of the upward ray with the triangles of (+1 where the triangle
///          faces up, -1 where it faces down) + sum over the boundary edges of multiplicity x
///          curtain_fraction(from - q, to - q),
/// exactly; the voxelizer evaluates it column by column with its exact crossing tests.
std::vector<BoundaryEdge> oriented_boundary(const std::vector<Eigen::Vector3i>& triangles);

/// What orient_consistently did.
struct Orientation {
  std::size_t reversed = 0;  ///< triangles turned to face the same way as their neighbours
  bool orientable = true;    ///< false: some patch cannot be oriented (a Moebius strip, ...)
};
/// Turns triangles so that each one faces the same way as its neighbours across every edge used by
/// exactly two triangles. Each connected patch keeps the orientation of the larger part (by area)
/// of its triangles, so an entirely inverted mesh stays inverted.
Orientation orient_consistently(const std::vector<Eigen::Vector3d>& vertices,
                                std::vector<Eigen::Vector3i>& triangles);

/// How voxelize decides which cell centres are inside.
enum class InsideTest {
  automatic,         ///< what voxelize does: crossings for closed, manifold meshes, else winding
  parity,            ///< z-ray crossings (a mesh that is not closed and manifold is an error)
  winding_number,    ///< |w| > 0.5, w summed over the triangles through the hierarchy (no warning)
  winding_boundary,  ///< |w| > 0.5, w from z-ray crossings and boundary curtains (no warning)
};
/// voxelize with a chosen inside test (defined in voxelize.cpp; for tests).
Result<ParticleSet> voxelize_with(const TriangleMesh& mesh, const VoxelizeOptions& options,
                                  InsideTest test);

}  // namespace motes::winding
