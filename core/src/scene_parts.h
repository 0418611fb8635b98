// The pieces of the scene loader (scene_load.cpp): shapes, bodies, cloth and ropes, and the checks
// on the whole scene. Private to motes_core.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "motes/scene.h"
#include "motes/shapes.h"
#include "scene_json.h"

namespace motes::scene_detail {

/// Largest settings.max_particles: particle indices are 32-bit and the core refuses 2^31.
constexpr std::int64_t kParticleLimit = (std::int64_t{1} << 31) - 1;
/// Default settings.max_particles.
constexpr std::int64_t kDefaultMaxParticles = 100'000'000;

/// State shared by every shape of one scene: meshes are loaded once per file and identical shape
/// descriptions give one shared ParticleSet.
struct ShapeCache {
  std::string base_dir;            ///< folder relative mesh paths start from
  double default_diameter = 0.0;   ///< settings.particle_diameter
  std::int64_t max_particles = 0;  ///< settings.max_particles
  std::map<std::string, std::shared_ptr<const TriangleMesh>> meshes;  ///< by resolved path
  std::map<std::string, std::shared_ptr<const ParticleSet>> shapes;   ///< by description
};

/// Reads a "shape" object and builds its particles (errors carry the shape's JSON path).
std::shared_ptr<const ParticleSet> read_shape(const Node& shape, ShapeCache& cache);

/// The mesh named by `file` (a path relative to cache.base_dir), loaded once per scene.
std::shared_ptr<const TriangleMesh> load_mesh_once(const Node& file, ShapeCache& cache);

/// Reads {"axis": [x, y, z], "degrees": a}.
Eigen::Quaterniond read_rotation(const Node& rotation);

/// One entry of the "bodies" array after expansion: its copies are scene.bodies[first, first +
/// copies).
struct BodyEntry {
  std::size_t first = 0;
  std::size_t copies = 0;
  std::string path;  ///< JSON pointer of the entry
};
/// Reads the "bodies" array into scene.bodies and scene.linked (materials must already be in
/// scene.materials), one BodyEntry per rigid body element into `entries`.
void read_bodies(const Node& bodies, ShapeCache& cache, Scene& scene,
                 std::vector<BodyEntry>& entries);

/// Index of a material by name; fails at `where` naming the known materials.
int find_material(const Node& where, const std::vector<Material>& materials);

/// A colour for pictures: [r, g, b] with each from 0 to 1 (sRGB), or "#rrggbb".
Eigen::Vector3d read_color(const Node& node);

/// Whether an entry of the "bodies" array is a cloth or a rope ("kind": "cloth" or "rope").
bool is_linked(const Node& entry);
/// Reads such an entry, the index-th of "bodies", into a LinkedSpec (materials must already be in
/// scene.materials; scene.linked holds the ones before it). Errors carry the JSON path; those of
/// make_cloth, make_mesh_cloth and make_rope that of the entry's "cloth" or "rope" object
/// (scene_linked.cpp). A cloth's "mesh" is loaded through `cache`.
LinkedSpec read_linked(const Node& entry, std::size_t index, ShapeCache& cache, const Scene& scene);

/// Whether an entry of the "bodies" array is a fluid ("kind": "fluid").
bool is_fluid(const Node& entry);
/// Reads such an entry, the index-th of "bodies", into a FluidSpec: its volume (a box, a sphere or
/// a closed mesh, loaded through `cache`) filled with particles at the rest spacing
/// (scene_fluid.cpp; docs/scene-format.md, "Fluids"). A fluid needs "contact_model": "position";
/// errors carry the JSON path.
FluidSpec read_fluid(const Node& entry, std::size_t index, ShapeCache& cache, const Scene& scene);

/// Largest distance a particle may travel in one substep at the start, as a fraction of its radius
/// (docs/reliability.md, "Initial speeds").
constexpr double kMaxStartTravel = 0.5;

/// Fails at the "velocity" (or, when the spin gives most of the speed, "angular_velocity") of
/// `entry`, a body, cloth or rope called `what` (e.g. body "ball"), when its fastest particle,
/// |v| + |w| x `reach` (the farthest particle centre from the centre of mass), would travel more
/// than kMaxStartTravel of its particle radius in the first substep of dt / substeps: its contacts
/// would be missed or come too deep to be resolved.
void check_initial_speed(const Node& entry, const std::string& what, const Eigen::Vector3d& v,
                         const Eigen::Vector3d& w, double reach, double diameter,
                         const Settings& settings);

/// Fails at /settings/dt when dt / substeps is above the explicit stability limit of the stiffest,
/// lightest contact the scene can make (docs/scene-format.md, "Stability").
void check_stability(const Scene& scene, const std::vector<BodyEntry>& entries);

}  // namespace motes::scene_detail
