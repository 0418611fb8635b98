// The host side of Simulation::upload (docs/architecture.md, "Scene building"): a scene laid out
// as the device holds it, by one builder per kind of object, before anything is written to the
// device. Private to motes_core.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "motes/backend/device.h"
#include "motes/cloth.h"
#include "motes/fluid.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "motes/soft.h"
#include "motes/status.h"
#include "shared/common.h"
#include "shared/fluid.h"
#include "shared/params.h"
#include "shared/shape_matching.h"

namespace motes::layout {

inline shared::vec4 to_vec4(const Eigen::Vector3d& v, double w) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()),
          static_cast<float>(w)};
}

/// What a scene needs on the device, counted (and checked) before anything is laid out, so that
/// an impossible size is refused before anything is allocated.
struct SceneCounts {
  std::uint64_t particles = 0;        ///< N
  std::uint64_t rigid_particles = 0;  ///< Nr: the rigid bodies' particles
  std::uint64_t rigid_bodies = 0;     ///< B
  std::uint64_t soft_particles = 0;   ///< the soft bodies' particles (Nl - Ns)
  std::uint64_t fluid_particles = 0;  ///< the fluids' particles (Ns - Nf)
  /// Every scene body's and fluid's particles: the cloths and ropes come after them (Nl).
  std::uint64_t body_particles = 0;
  std::uint64_t constraints = 0;  ///< the cloths' and ropes' links and attachments
  /// The grid's largest particle diameter: the scene's, or on a rank of a run over MPI ranks the
  /// whole scene's (HaloLists::scene_diameter) when that is larger.
  double max_diameter = 0.0;
  /// The fluids' largest support h = 2 d (docs/fluids.md, "Support radius and the neighbour
  /// lists"); 0 without fluid.
  double max_fluid_support = 0.0;
  bool impulses = false;  ///< settings.contact_model is Impulses
};

/// Checks the scene's settings and objects (errors name scene.source) and counts them; `bodies`
/// is scene_bodies(scene), `halo` a rank's lists or null.
Result<SceneCounts> count_scene(const Scene& scene, const SceneBodies& bodies,
                                const HaloLists* halo);

/// The device's sizes from the counts: all but those the builders find (absorb, clusters,
/// cluster_members, link_exclusions and the halo's).
Sizes count_sizes(const Scene& scene, const SceneCounts& counts, const HaloLists* halo);

/// A dynamic one-particle body without spin, laid out as a particle (no body state); never with
/// impulse contacts, where an impulse at the contact point makes any sphere spin.
bool is_free_sphere(const BodySpec& body, bool impulses);

/// Every particle in device order: rigid [0, Nr), free spheres [Nr, Nf), fluid [Nf, Ns), soft
/// [Ns, Nl), cloth and rope [Nl, N) (ParticlePos, ParticleVel, ParticleBody, ParticleMaterial).
struct ParticleLayout {
  std::vector<shared::vec4> pos, vel;
  std::vector<std::uint32_t> body, material;
};

/// The rigid bodies: ParticleLocal (Nr), the body state and inverse inertia (B each), BodyFirst
/// (B + 1).
struct RigidLayout {
  std::vector<shared::vec4> local;
  std::vector<shared::vec4> pos, quat, vel, angmom, angvel, inv_inertia;
  std::vector<std::uint32_t> first;
};

/// The soft bodies' shape-matching clusters: Clusters, ClusterMembers, ClusterFrames (the
/// identity before the first fit) and ClusterGather.
struct SoftLayout {
  SoftClusters clusters;
  std::vector<shared::ClusterFrame> frames;
  std::vector<std::uint32_t> gather;
};

/// The cloths and ropes: Constraints grouped by colour, and LinkExclusions.
struct LinkedLayout {
  ConstraintColouring colouring;
  std::vector<std::uint32_t> exclusions;
};

/// ContactLaws and Planes.
struct TableLayout {
  std::vector<shared::ContactLaw> laws;
  std::vector<shared::PlaneData> planes;
};

/// A rank's halo lists as device indices (HaloIndex: send particles, send rigid bodies, receive
/// particles, receive rigid bodies) and the entries of each part.
struct HaloLayout {
  std::vector<std::uint32_t> index;
  std::array<std::uint32_t, 4> entries{};
};

/// Everything Simulation::upload writes to the device, and the host's facts about it.
struct HostLayout {
  Sizes sizes;
  shared::StepParams params{};
  /// Per scene body, then per cloth and rope (scene_bodies, completed by the builders).
  std::vector<BodyInfo> bodies;
  /// Per scene body: its rigid body index, a free sphere's or soft body's first particle (its
  /// only one for a free sphere), a cloth's or rope's first particle (Simulation::device_index_).
  std::vector<std::uint32_t> device_index;
  /// (scene body, orientation) of the free spheres not at the identity orientation.
  std::vector<std::pair<std::uint32_t, shared::vec4>> sphere_turns;
  ParticleLayout particles;
  RigidLayout rigid;
  SoftLayout soft;
  LinkedLayout linked;
  TableLayout tables;
  /// FluidMaterials: one entry per material with fluid, none without (motes/fluid.h).
  std::vector<shared::FluidMaterial> fluid_materials;
  /// The emitters' particles (parked: inverse mass 0 in ParticleVel until they leave).
  std::vector<EmitterRange> emitters;
  HaloLayout halo;
};

/// The scene's bodies in its order, each by the builder of its kind (rigid bodies, free spheres,
/// soft bodies): every body particle, the rigid bodies, the soft bodies' clusters, the bodies'
/// masses, free spheres and cluster ranges. `out.bodies` is scene_bodies(scene)'s.
Status build_bodies(const Scene& scene, const SceneCounts& counts, HostLayout& out);
/// The cloths and ropes after them (build_bodies first: attachments hold on to its bodies):
/// their particles, masses, constraints and link exclusions; sizes absorb and link_exclusions.
Status build_linked(const Scene& scene, const SceneCounts& counts, HostLayout& out);
/// The fluids (after build_linked: their scene entries follow the cloths' and ropes'): their
/// particles [Nf, Ns), one body word each, the FluidMaterials table; sizes fluid_particles.
Status build_fluids(const Scene& scene, const SceneCounts& counts, HostLayout& out);
/// The contact laws of every pair of materials, and the planes.
TableLayout build_tables(const Scene& scene);
/// A rank's halo lists (after build_bodies and build_linked); sizes halo_index, halo_data and
/// partition.
Status build_halo(const std::string& source, const HaloLists& halo, HostLayout& out);
/// The step's parameters (after build_bodies: the soft bodies' clusters).
shared::StepParams build_params(const Settings& settings, const SceneCounts& counts,
                                const HostLayout& layout);

/// The setup's fingerprint (Simulation::setup_hash) and the hash of the particles' radii and
/// inverse masses, from the host's copies: the same on every backend.
struct Fingerprint {
  std::uint64_t setup = 0;
  std::uint64_t particle_w = 0;
};
Fingerprint fingerprint(const Settings& settings, const HostLayout& layout);

}  // namespace motes::layout
