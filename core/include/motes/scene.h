// Scenes: what a JSON scene file describes (docs/scene-format.md), after loading and validation.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "motes/api.h"
#include "motes/shapes.h"
#include "motes/status.h"

MOTES_API_BEGIN
namespace motes {

/// A named material: density and the contact law of its particles.
struct Material {
  std::string name;
  double density = 1000.0;  ///< kg/m^3
  double stiffness = 0.0;   ///< k (N/m)
  double damping = 0.0;     ///< gamma_n (1/s): normal dashpot force = gamma_n m* v_n
  double tangential = 0.0;  ///< gamma_t (1/s): tangential force = gamma_t m* v_t
  double friction = -1.0;   ///< Coulomb cap mu on the tangential force; < 0: no cap
  /// Impulse contacts (Settings::contact_model): coefficient of restitution e in [0, 1] (a pair
  /// takes the mean of its two materials').
  double restitution = 0.0;
  /// Fluids (issue 29, docs/fluids.md; a fluid body of this material): the rest density rho_0
  /// (kg/m^3); 0: `density`.
  double rest_density = 0.0;
  double viscosity = 0.01;  ///< fluids: XSPH viscosity c (dimensionless, 0 to 1)
  double vorticity = 0.0;   ///< fluids: vorticity confinement eps (m/s)
  double cohesion = 0.0;    ///< fluids: Akinci et al. 2013's cohesion gamma
  double adhesion = 0.0;    ///< fluids: Akinci et al. 2013's adhesion beta (to solids)
};

/// How rigid bodies meet each other and the planes (docs/architecture.md, "Impulse contacts" and
/// "Position contacts"). Soft bodies, cloth and ropes meet everything through the force law (with
/// position contacts a scene may not have them yet: issue 27).
enum class ContactModel {
  Forces,    ///< Harada's DEM: spring, dashpot and tangential force per particle contact
  Impulses,  ///< Guendelman et al. 2003: impulses with restitution and Coulomb friction
  Positions  ///< Müller et al. 2020: position constraints per substep, frame-sized steps
};

/// True when rigid bodies meet each other and the planes without the force law (impulse or
/// position contacts): they need no stiffness and set no stability limit among themselves.
inline bool rigid_contacts_without_forces(ContactModel model) {
  return model != ContactModel::Forces;
}

/// Substeps of a step with position contacts when the scene does not give them.
constexpr int kPositionSubsteps = 8;

/// Global settings of a scene.
struct Settings {
  double dt = 1.0e-4;                        ///< time of one step (s)
  int substeps = 1;                          ///< physics substeps per step (each dt/substeps)
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  ///< m/s^2
  double particle_diameter = 0.01;           ///< default particle diameter for shapes (m)
  bool clamp_attraction = false;             ///< forbid attractive (tensile) normal forces
  double duration = 1.0;                     ///< default simulated time for `motes run` (s)
  double output_interval = 1.0 / 60.0;       ///< simulated time between output frames (s)
  /// Neighbour-list skin (m): lists are rebuilt when a particle has moved 0.45 of it; < 0: 10% of
  /// the largest particle diameter. 0 rebuilds every substep.
  double neighbour_skin = -1.0;
  int neighbour_capacity = 16;  ///< list entries per particle; beyond, a particle walks the grid
  /// Cloth and ropes: relaxation sweeps over every constraint colour per substep (Jakobsen).
  int constraint_iterations = 8;
  /// Fluids: Jacobi sweeps of the density constraint per substep (docs/fluids.md; motes/fluid.h
  /// kFluidIterations).
  int fluid_iterations = 2;
  /// Cloth and ropes: their particles' velocities decay at this rate (1/s); 0 = none.
  double link_damping = 0.0;
  /// Rigid-body contacts by forces (default), by impulses ("contact_model": "impulse") or by
  /// positions ("position": each step a frame, settings.substeps of it solved once each).
  ContactModel contact_model = ContactModel::Forces;
  /// Impulse contacts: sweeps over every contact per substep, spread over impulse_substeps (each
  /// gets ceil(impulse_iterations / impulse_substeps): the first half correct overlaps, the rest
  /// relax; docs/architecture.md, "Impulse contacts").
  int impulse_iterations = 16;
  /// Impulse contacts: the impulse stage's own substeps per substep (the contacts found once).
  int impulse_substeps = 4;
  /// Impulse contacts: a particle whose neighbour list a build leaves unchanged keeps its
  /// contacts' accumulated impulses (warm start) through the build. Runs over MPI ranks turn it
  /// off (the memory does not travel with a partition yet: docs/scale-out.md), so that they stay
  /// bitwise equal to one process run with it off.
  bool impulse_memory_across_builds = true;
  Material contact;  ///< defaults for materials' missing fields
};

enum class BodyKind { Dynamic, Static };

/// What a soft body's goal shape may do besides rotating and translating (Mueller et al. 2005).
enum class SoftMode {
  Rigid,     ///< the rest shape, rotated and moved
  Linear,    ///< blended with the best linear fit (volume kept)
  Quadratic  ///< blended with the best quadratic fit (twists and bends)
};

/// A dynamic body made soft by shape matching: its particles move freely under their contact
/// forces, then each is pulled toward the goal of its clusters (docs/architecture.md, "Soft
/// bodies"). Clusters split the body's bounding box into a grid of cells, each grown by half a
/// cell on every side so that neighbouring clusters overlap and a long body can bend.
struct SoftSpec {
  double stiffness = 0.5;  ///< alpha: fraction of the way to the goal per substep, in (0, 1]
  /// > 0: the shape's natural frequency (Hz) instead of `stiffness`, the same at any time step:
  /// alpha = (2 pi frequency dt / substeps)^2 (at most 1); a body then sags g / (2 pi f)^2 under
  /// its own weight.
  double frequency = 0.0;
  /// Rate (1/s) at which the particles' velocities relative to their cluster's rigid motion decay
  /// (momentum-conserving internal damping; 0: none, the body rings).
  double damping = 0.0;
  SoftMode mode = SoftMode::Rigid;
  double beta = 0.0;                     ///< linear and quadratic modes: weight of the fit
  std::array<int, 3> clusters{1, 1, 1};  ///< cells along the body's x, y, z (rest frame)
};

/// One rigid or soft body (a repeated body in the file becomes several BodySpecs).
struct BodySpec {
  std::string name;
  BodyKind kind = BodyKind::Dynamic;
  std::shared_ptr<const ParticleSet> shape;  ///< particles in the shape frame (shared by repeats)
  int material = 0;                          ///< index into Scene::materials
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< where the centre of mass goes
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< rad/s, world frame
  std::optional<Eigen::Vector3d> color;  ///< sRGB, each 0..1, for pictures (docs/rendering.md)
  std::optional<SoftSpec> soft;          ///< set: a soft body (dynamic only), no angular velocity
};

enum class LinkedKind { Rope, Cloth };

/// A distance constraint between two particles of one cloth or rope (indices into its points); its
/// rest length is their distance as built.
struct LinkSpec {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  double stiffness = 1.0;  ///< fraction of the error one projection removes, in (0, 1]
};

/// A cloth or rope point held by a rigid or static body: a link of the point's rest distance to
/// the body's nearest particle, relaxed with the others; the body takes what the link does to
/// that particle (docs/architecture.md, "Cloth and ropes").
struct LinkAttachment {
  std::uint32_t point = 0;  ///< index into LinkedSpec::points
  std::string body;         ///< name of a rigid or static BodySpec
};

/// A cloth or a rope (Jakobsen 2001): equal spheres on a lattice or at a mesh's vertices, joined
/// by distance constraints, integrated by position Verlet and relaxed colour by colour; they
/// collide with everything through the one grid, themselves included (not within two lattice
/// steps, or two links for a cloth from a mesh). Built by make_rope, make_cloth and
/// make_mesh_cloth (motes/cloth.h).
struct LinkedSpec {
  std::string name;
  LinkedKind kind = LinkedKind::Rope;
  int material = 0;                     ///< index into Scene::materials; each particle weighs
                                        ///< density x pi/6 diameter^3, as a lone sphere
  double diameter = 0.0;                ///< particle diameter (m)
  std::vector<Eigen::Vector3d> points;  ///< world positions of the particles
  /// (u, v) of each point; a rope: (i, 0). Empty for a cloth made from a triangle mesh: its
  /// particles within two links of each other do not touch (link_neighbourhoods).
  std::vector<std::array<std::uint32_t, 2>> lattice;
  std::vector<LinkSpec> links;
  std::vector<std::uint32_t> pinned;     ///< points held fixed in space (inverse mass 0)
  std::vector<LinkAttachment> attached;  ///< points held by bodies (none also pinned)
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> color;  ///< sRGB, each 0..1, for pictures
};

/// A stream of liquid from a nozzle (docs/fluids.md, "Emitters"): layers of particles leave a
/// disc across `direction` at `speed`, `rate` particles a second, from `start` until `stop` or
/// until `max_particles` have left. The disc holds the lattice points (spacing d) of the nozzle
/// (emitter_nozzle); a layer leaves every `layer_period` s.
struct FluidEmitter {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();     ///< the nozzle's centre (m)
  Eigen::Vector3d direction{0.0, -1.0, 0.0};              ///< unit vector the stream leaves along
  double speed = 1.0;                                     ///< m/s
  double rate = 1000.0;                                   ///< particles per second
  std::uint64_t max_particles = 0;                        ///< the most it ever emits (> 0)
  double start = 0.0;                                     ///< s
  double stop = std::numeric_limits<double>::infinity();  ///< s
  std::vector<Eigen::Vector3d> nozzle;                    ///< one layer's offsets from position (m)
  double layer_period = 0.0;  ///< s between layers: nozzle.size() / rate
};

/// The nozzle of an emitter of particles of diameter d (spacing d), `rate` particles a second at
/// `speed` along unit `direction`: the points i u + j w (u, w across the direction) of the square
/// lattice within the disc whose count is closest to rate d / speed (a layer per d of travel, so
/// that the stream is spaced d along it), at least one.
std::vector<Eigen::Vector3d> emitter_nozzle(const Eigen::Vector3d& direction, double rate,
                                            double speed, double d);
/// The most particles a nozzle holds (a disc about 3.6 m across at 1 cm).
constexpr std::int64_t kEmitterNozzleLimit = 100000;

/// A volume of liquid (issue 29, docs/fluids.md): equal particles on a cubic lattice of the rest
/// spacing (fluid_rest_spacing: 1.003 x `diameter`), each of mass rest_density x diameter^3,
/// filling a box, a sphere or a mesh's volume; or an emitter's particles, parked (inverse mass 0,
/// far below its nozzle: `points` are their places) until they leave it.
struct FluidSpec {
  std::string name;
  int material = 0;                     ///< index into Scene::materials (its fluid fields)
  double diameter = 0.0;                ///< particle diameter = rest spacing d (m)
  std::vector<Eigen::Vector3d> points;  ///< world positions of the particles
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> color;  ///< sRGB, each 0..1, for pictures
  std::optional<FluidEmitter> emitter;   ///< set: the particles leave this emitter
};

/// Where an emitter's particles wait (m): far enough below its nozzle (kEmitterParkDepth) that
/// nothing reaches them, kEmitterParkSpacing diameters apart so that no two are neighbours.
constexpr double kEmitterParkDepth = 1000.0;
constexpr double kEmitterParkSpacing = 4.0;
std::vector<Eigen::Vector3d> emitter_parking(const FluidEmitter& e, double d);

/// A static analytic half-space: solid below the plane (opposite to the normal).
struct PlaneSpec {
  std::string name;
  Eigen::Vector3d normal{0.0, 1.0, 0.0};  ///< unit normal pointing into free space
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int material = 0;
};

/// Where pictures of the scene are taken from (`motes run --render`, docs/rendering.md).
struct CameraSpec {
  Eigen::Vector3d position{0.0, 0.0, 1.0};           ///< the eye (m)
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  ///< the point in the image centre (m)
  Eigen::Vector3d up{0.0, 1.0, 0.0};  ///< unit vector; the image's up is its part across the view
  double fov = 40.0;                  ///< vertical field of view (degrees, 0 < fov < 180)
};

struct Scene {
  std::string source;  ///< file it was loaded from (or "<built-in>")
  Settings settings;
  std::vector<Material> materials;
  std::vector<BodySpec> bodies;
  std::vector<LinkedSpec> linked;  ///< cloth and ropes; in outputs they follow the bodies
  std::vector<FluidSpec> fluids;   ///< liquids ("kind": "fluid"; not simulated yet)
  std::vector<PlaneSpec> planes;
  std::optional<CameraSpec> camera;  ///< none: pictures fit a camera to the particles

  [[nodiscard]] std::size_t particle_count() const;
};

/// Loads and validates a scene file. Errors read "FILE: /json/path: reason", or
/// "FILE:LINE:COLUMN: reason" for JSON syntax errors.
Result<Scene> load_scene_file(const std::string& path);
/// Same, from text; `source` names it in messages; relative mesh paths resolve from base_dir.
Result<Scene> load_scene_text(const std::string& text, const std::string& source,
                              const std::string& base_dir);

/// The scene `motes run` uses without arguments (examples/scenes/dominoes.json, built in).
Result<Scene> builtin_default_scene();

}  // namespace motes
MOTES_API_END
