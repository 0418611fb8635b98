// Shapes to particles: primitives, meshes (assimp) and voxelization, and mass properties.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

#include "motes/api.h"
#include "motes/status.h"

MOTES_API_BEGIN
namespace motes {

/// Equal spheres filling a shape, in the shape's own frame (metres).
struct ParticleSet {
  std::vector<Eigen::Vector3f> points;  ///< sphere centres
  double diameter = 0.0;                ///< sphere diameter = lattice spacing
  /// Volume that gives each particle its mass (density x volume). 0: diameter^3, the particle's
  /// lattice cell, so a filled shape weighs density x its volume. A lone sphere uses pi/6 d^3.
  double particle_volume = 0.0;
  /// Things the user should know about how the particles were made, one sentence each, naming
  /// the mesh file (e.g. an open mesh filled by its winding number). Empty for primitives.
  std::vector<std::string> warnings;
};

/// A box of size sx x sy x sz, centred at the origin: the centres of the cells of a lattice of
/// spacing `diameter` that lie inside the box (a box of n*d per side gives exactly n^3).
Result<ParticleSet> box_particles(const Eigen::Vector3d& size, double diameter);
/// Exactly nx*ny*nz particles on a lattice of spacing `diameter`, centred at the origin.
Result<ParticleSet> box_lattice(const Eigen::Vector3i& counts, double diameter);
/// A solid sphere of the given radius, centred at the origin.
Result<ParticleSet> sphere_particles(double radius, double diameter);
/// A solid cylinder along y, centred at the origin.
Result<ParticleSet> cylinder_particles(double radius, double height, double diameter);
/// A capsule along y: a cylinder of the given height with hemispherical caps of the given radius.
Result<ParticleSet> capsule_particles(double radius, double height, double diameter);

/// A triangle mesh, as loaded from a file.
struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;  ///< vertex indices, counter-clockwise seen from outside
  std::string source;                      ///< file it came from (for messages)
};

/// Loads OBJ, PLY, STL, OFF and the other formats assimp reads; triangulates and merges
/// coincident vertices. Errors name the file and the reason.
Result<TriangleMesh> load_mesh(const std::string& path);

/// Number of edges used by other than exactly two triangles (0 for a closed, manifold mesh).
std::size_t count_open_edges(const TriangleMesh& mesh);

/// Particle size: exactly one of diameter > 0 or target_count > 0.
struct VoxelizeOptions {
  double diameter = 0.0;         ///< lattice spacing and sphere diameter (m)
  std::size_t target_count = 0;  ///< choose the diameter that gives the count nearest to this
};

/// Fills a mesh with particles: the centres of a lattice of diameter-sized cells that lie inside.
/// A closed, manifold mesh: rays along z through the cell centres, odd crossing count = inside
/// (where its surface overlaps itself, a non-zero crossing count). An open or non-manifold mesh:
/// generalized winding number |w| > 0.5 = inside, with a note in ParticleSet::warnings
/// (docs/scene-format.md, "Open and non-manifold meshes"). A mesh that encloses no volume, an
/// empty result or a bad option is an error naming mesh.source.
Result<ParticleSet> voxelize(const TriangleMesh& mesh, const VoxelizeOptions& options);

/// Mass, centre of mass and inertia of equal spheres of the given density, each of mass
/// density * particle_volume (default diameter^3, its lattice cell), with the per-sphere term
/// 2/5 m r^2.
struct MassProperties {
  double mass = 0.0;
  double particle_mass = 0.0;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about the centre, shape frame
  /// Principal moments (ascending) and the rotation from the principal frame to the shape frame
  /// (a proper rotation: det = +1).
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();
  Eigen::Quaterniond principal_frame = Eigen::Quaterniond::Identity();
};
MassProperties mass_properties(const ParticleSet& particles, double density);

}  // namespace motes
MOTES_API_END
