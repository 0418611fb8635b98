// The pieces of the scene loader (scene_load.cpp): shapes, bodies and the checks on the whole
// scene. Private to motes_core.
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

/// Reads {"axis": [x, y, z], "degrees": a}.
Eigen::Quaterniond read_rotation(const Node& rotation);

/// One entry of the "bodies" array after expansion: its copies are scene.bodies[first, first +
/// copies).
struct BodyEntry {
  std::size_t first = 0;
  std::size_t copies = 0;
  std::string path;  ///< JSON pointer of the entry
};
/// Reads the "bodies" array into scene.bodies (materials must already be in scene.materials),
/// one BodyEntry per array element into `entries`.
void read_bodies(const Node& bodies, ShapeCache& cache, Scene& scene,
                 std::vector<BodyEntry>& entries);

/// Index of a material by name; fails at `where` naming the known materials.
int find_material(const Node& where, const std::vector<Material>& materials);

/// Fails at /settings/dt when dt / substeps is above the explicit stability limit of the stiffest,
/// lightest contact the scene can make (docs/scene-format.md, "Stability").
void check_stability(const Scene& scene, const std::vector<BodyEntry>& entries);

}  // namespace motes::scene_detail
