// Cloth and ropes (Jakobsen 2001): building them from a rectangle or a polyline, and colouring
// their constraint graph so that each colour can be relaxed in parallel (docs/architecture.md,
// "Cloth and ropes").
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "motes/api.h"
#include "motes/scene.h"
#include "motes/shapes.h"
#include "motes/status.h"
#include "shared/links.h"

MOTES_API_BEGIN
namespace motes {

/// Largest lattice side (particles along u or v) and number of cloth and rope objects in one
/// scene: a particle's lattice place travels in its ParticleBody word (shared/links.h).
constexpr std::uint32_t kLinkedMaxSide = MOTES_LINKED_MAX_SIDE;
constexpr std::uint32_t kLinkedMaxObjects = MOTES_LINKED_MAX_OBJECTS;

/// Mass of one cloth or rope particle: density x pi/6 diameter^3, a lone sphere's.
double linked_particle_mass(double density, double diameter);

/// Options of a rope: `count` particles evenly spaced by arc length along a polyline (`path`, or
/// the segment from `from` to `to` when `path` is empty), each joined to the next; with `bend`,
/// also each to the one after next (resists folding). A link's rest length is the straight
/// distance between its particles as laid out, so a path that sags makes a slack rope.
struct RopeOptions {
  Eigen::Vector3d from = Eigen::Vector3d::Zero();
  Eigen::Vector3d to = Eigen::Vector3d::UnitX();
  std::vector<Eigen::Vector3d> path;  ///< at least two points when given
  int count = 2;
  double diameter = 0.01;
  bool bend = false;
  double stiffness = 1.0;
  double bend_stiffness = 1.0;
};
/// A rope (kind Rope; name, material, pins, velocity and colour left to the caller). Errors name
/// the bad option.
Result<LinkedSpec> make_rope(const RopeOptions& options);

/// Options of a cloth: nu x nv particles at corner + edge_u * i / (nu - 1) + edge_v * j / (nv - 1),
/// with structural links (to the next in u and in v), shear links (both diagonals of each
/// square) and, with `bend`, bend links (to the one after next in u and in v).
struct ClothOptions {
  Eigen::Vector3d corner = Eigen::Vector3d::Zero();
  Eigen::Vector3d edge_u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d edge_v = Eigen::Vector3d::UnitZ();
  int nu = 2;
  int nv = 2;
  double diameter = 0.01;
  bool bend = true;
  double stiffness = 1.0;
  double bend_stiffness = 1.0;
};
/// A cloth (kind Cloth; name, material, pins, velocity and colour left to the caller).
Result<LinkedSpec> make_cloth(const ClothOptions& options);

/// Index of the cloth point at lattice place (i, j) (row-major in u).
inline std::uint32_t cloth_index(const ClothOptions& options, int i, int j) {
  return static_cast<std::uint32_t>(j * options.nu + i);
}

/// Options of a cloth made from a triangle mesh: a particle at every vertex that a triangle uses,
/// a structural link along every edge and, with `bend`, a bend link across every edge that two
/// triangles share (between the two vertices opposite it). Rest lengths are the mesh's.
struct MeshClothOptions {
  double diameter = 0.01;
  bool bend = true;
  double stiffness = 1.0;
  double bend_stiffness = 1.0;
};
/// A cloth from `mesh` (kind Cloth, no lattice; name, material, pins, velocity and colour left to
/// the caller). Errors name mesh.source: no triangles, more than kLinkedMaxMeshPoints vertices
/// in use, a non-finite vertex, a bad option.
Result<LinkedSpec> make_mesh_cloth(const TriangleMesh& mesh, const MeshClothOptions& options);

/// make_mesh_cloth refuses a mesh whose sum over vertices of (links per vertex)^2, the bound on
/// the pairs within two links, exceeds this many per vertex (a regular mesh has about 150).
constexpr std::uint64_t kMaxNearPerPoint = 512;

/// Most vertices of a cloth made from a mesh (the vertex travels in 20 bits of ParticleBody).
constexpr std::uint32_t kLinkedMaxMeshPoints = MOTES_LINKED_MAX_MESH_POINTS;

/// For each of `count` points, the other points within two links of it (the links' graph),
/// ascending: point k's are list[start[k], start[k + 1]). Such particles never touch
/// (LinkExclusions, shared/links.h).
struct LinkNeighbourhoods {
  std::vector<std::uint32_t> start;  ///< count + 1 entries
  std::vector<std::uint32_t> list;
};
LinkNeighbourhoods link_neighbourhoods(const std::vector<LinkSpec>& links, std::uint32_t count);

/// Constraints grouped by colour: no two constraints of one colour share a particle. Colour c is
/// constraints[first[c], first[c + 1]).
struct ConstraintColouring {
  std::vector<shared::Constraint> constraints;
  std::vector<std::uint32_t> first;  ///< colours + 1 entries
  [[nodiscard]] std::size_t colours() const { return first.empty() ? 0 : first.size() - 1; }
};
/// Greedy colouring in the given order (each constraint takes the smallest colour neither of its
/// particles has yet), then a stable sort by colour: deterministic, computed once on the host, so
/// every backend relaxes the same constraints in the same order.
ConstraintColouring colour_constraints(const std::vector<shared::Constraint>& constraints,
                                       std::uint32_t particles);

}  // namespace motes
MOTES_API_END
