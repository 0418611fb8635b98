// motes::Simulation: owns the step and the host view of the state; runs on any Device.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "motes/api.h"
#include "motes/backend/device.h"
#include "motes/energy.h"
#include "motes/fluid.h"
#include "motes/scene.h"
#include "motes/status.h"
#include "shared/common.h"

MOTES_API_BEGIN
namespace motes {

/// State read back from the device (vec4 layouts as in motes::Buffer), in the scene's order: body
/// b is the scene's b-th body (then its cloths and ropes) and its particles are
/// [BodyInfo::first_particle, + particle_count). A free sphere's body state is its particle's, a
/// cloth's or rope's the mean of its particles' (orientation fixed, no angular momentum).
struct Snapshot {
  double time = 0.0;
  std::uint64_t step = 0;
  std::vector<shared::vec4> particle_pos;    ///< xyz, w = radius
  std::vector<shared::vec4> particle_vel;    ///< xyz, w = inverse mass
  std::vector<std::uint32_t> particle_body;  ///< scene body index
  std::vector<shared::vec4> body_pos;        ///< centre of mass, w = inverse mass
  std::vector<shared::vec4> body_quat;
  std::vector<shared::vec4> body_vel;
  std::vector<shared::vec4> body_angmom;
  std::vector<shared::vec4> body_angvel;
  /// Impulse contacts only (else empty): the part of each body's centre of mass below its float
  /// (Buffer::BodyPosLow; zero for bodies that are not rigid). Empty when restoring: zeros.
  std::vector<shared::vec4> body_pos_low;
  /// Rotation of each shape-matching cluster's last fit (device order): the next fit starts
  /// from it, so a bitwise resume needs it.
  std::vector<shared::vec4> cluster_rotation;
  /// Impulse contacts only, and only when asked for (Simulation::read_plane_impulses): each
  /// particle's accumulated impulse with each plane, kept from substep to substep whatever the
  /// lists do (P per particle in the scene's particle order; zero for particles that are not
  /// rigid).
  std::vector<shared::vec4> plane_impulse;
};

/// Static facts about a body, kept on the host.
struct BodyInfo {
  std::string name;
  BodyKind kind = BodyKind::Dynamic;
  double mass = 0.0;
  std::uint32_t first_particle = 0;  ///< in the scene's particle order (Snapshot)
  std::uint32_t particle_count = 0;
  /// A dynamic one-particle body without spin, integrated as a particle (no body state on the
  /// device); otherwise a rigid body.
  bool free_sphere = false;
  /// A cloth or a rope (Scene::linked; they follow the scene's bodies): its body state in a
  /// Snapshot is the mean position and velocity of its particles (orientation fixed).
  bool linked = false;
  /// A soft body (shape matching): like a cloth, its body state in a Snapshot is the mean
  /// position and velocity of its particles.
  bool soft = false;
  /// A fluid (Scene::fluids; they follow the cloths and ropes): like a soft body, its body state
  /// in a Snapshot is the mean position and velocity of its particles.
  bool fluid = false;
  /// A soft body's shape-matching clusters: Snapshot::cluster_rotation [first_cluster,
  /// + cluster_count).
  std::uint32_t first_cluster = 0;
  std::uint32_t cluster_count = 0;

  /// A rigid body on the device, a static one too: it has body state (BodyPos ... BodyAngVel),
  /// and in a halo its five vectors travel after its particles' (shared/halo.h).
  [[nodiscard]] bool has_body_state() const { return !free_sphere && !linked && !soft && !fluid; }
};

/// A scene's bodies, then its cloths and ropes, then its fluids, in the scene's order with the
/// particle ranges of a Snapshot (BodyInfo's name, kind, first_particle, particle_count, soft,
/// linked; a body's mass, free_sphere and clusters are the Simulation's: Simulation::bodies), with
/// the particle count and the largest particle diameter. Simulation::create lays a scene out from
/// it; a run over MPI ranks describes the whole scene with it.
struct SceneBodies {
  std::vector<BodyInfo> bodies;
  std::uint64_t particles = 0;
  double largest_diameter = 0.0;
};
SceneBodies scene_bodies(const Scene& scene);

/// Neighbour-list figures since the simulation was created (NeighbourState).
struct NeighbourStats {
  std::uint32_t builds = 0;         ///< list builds so far (the first at the first step)
  std::uint32_t over_capacity = 0;  ///< particles with more than K neighbours at the last build
  std::uint32_t max_count = 0;      ///< the largest neighbour count at the last build
  bool rebuild_pending = false;     ///< the next step rebuilds the lists
};

/// A run over MPI ranks (motes/distributed.h, docs/scale-out.md): the bodies (indices in the
/// simulation's body order) whose state this rank sends to its neighbours after every step,
/// grouped by the rank they go to, and those whose state it receives, grouped by the rank they
/// come from. Their state travels packed (shared/halo.h): every listed body's particles
/// (position, velocity) in list order, then the rigid bodies' five vectors in list order.
struct HaloLists {
  std::vector<std::uint32_t> send;
  std::vector<std::uint32_t> receive;
  /// The whole scene's particle count and largest particle diameter: each rank builds the grid
  /// one process would (table size, cell size, skin), so that cells hash alike on every rank and
  /// a particle meets its contact partners in the same order at any rank count.
  std::uint32_t scene_particles = 0;
  double scene_diameter = 0.0;
};

/// What the motion guard found (Simulation::check_motion, docs/reliability.md "Guards while
/// running"): the particle that travels the most of its diameter per substep, and the scene's
/// mechanical energy against the energy guard's reference.
struct MotionReport {
  std::uint64_t step = 0;
  double time = 0.0;
  bool moving = false;         ///< some particle moves (the fields below describe the fastest)
  double travel = 0.0;         ///< its travel per substep, in its own diameters
  double speed = 0.0;          ///< its speed (m/s)
  double diameter = 0.0;       ///< its diameter (m)
  std::uint32_t body = 0;      ///< its scene body
  std::uint32_t particle = 0;  ///< its index in the scene's particle order (Snapshot)
  /// The largest dt (at the run's substeps) at which it would travel kSafeTravel of its diameter.
  double safe_dt = 0.0;
  /// Non-empty when travel > kSafeTravel: contacts can be missed (tunnelling); names step, body,
  /// particle, speed and the largest safe dt.
  std::string warning;

  // The energy guard (J; potential energy from the reference point chosen at upload).
  double kinetic_energy = 0.0;
  double potential_energy = 0.0;
  double energy = 0.0;  ///< kinetic + potential
  /// What it is compared against: E0 (the reference's kinetic + potential + stored contact
  /// energy), the margin above it, and the step the reference was taken at.
  EnergyReference reference;
  /// energy - E0: how much the energy rose since the reference (negative: it fell).
  double rise = 0.0;
  /// The largest rise seen by the checks since the reference (this one included).
  double largest_rise = 0.0;
  /// The item with the most kinetic energy: its kinetic energy, scene body, and for a particle
  /// item (free sphere, soft body, cloth, rope) its scene particle (MechanicalEnergy::kNone for a
  /// rigid body; both kNone when nothing counts).
  double largest_kinetic = 0.0;
  std::uint32_t largest_kinetic_body = MechanicalEnergy::kNone;
  std::uint32_t largest_kinetic_particle = MechanicalEnergy::kNone;
  /// The fastest any particle can be while the energy holds (energy_speed_limit; infinity when
  /// nothing can move).
  double speed_limit = 0.0;
};

struct CheckpointRun;  // motes/checkpoint.h

class Simulation {
 public:
  /// Builds the particles and bodies of a scene and uploads them to the device.
  static Result<std::unique_ptr<Simulation>> create(const Scene& scene,
                                                    std::unique_ptr<Device> device);
  /// The same for one rank of a run over MPI ranks: with the halo lists on the device
  /// (halo_pack, halo_unpack) and a partition reference (partition_displacement).
  static Result<std::unique_ptr<Simulation>> create(const Scene& scene,
                                                    std::unique_ptr<Device> device,
                                                    const HaloLists& halo);

  /// Ends a simulation and hands its device back, to be given to the next Simulation::create
  /// (which allocates anew): a new scene on the same device without opening it again (CUDA
  /// context and kernels, Vulkan device and pipelines).
  static std::unique_ptr<Device> take_device(std::unique_ptr<Simulation> sim);

  /// Advances `count` steps of settings.dt (each settings.substeps substeps).
  Status step(std::uint64_t count = 1);

  /// Reads the state back (waits for the device).
  Result<Snapshot> snapshot();
  /// With impulse contacts, fills state.plane_impulse (the contacts with the planes remember
  /// their accumulated impulse across list rebuilds; write_state restores it); otherwise
  /// empties it.
  Status read_plane_impulses(Snapshot& state);
  /// 64-bit FNV-1a hash of every particle and body buffer's bytes: equal hashes = equal states.
  Result<std::uint64_t> state_hash();
  /// Checks every body and particle for NaN or infinity; the error names step, body and particle.
  Status check_finite();
  /// The motion and energy guards (reductions on the device, the kernel families particles_check
  /// and energy_reduce; cheap: call it at output frames and at least every kGuardInterval
  /// steps). The first call, and the first after the state was changed from outside
  /// (set_body_velocities, write_state, load_state, rebase_energy), takes the energy reference
  /// E0 (motes/energy.h: the kinetic and potential energy, plus the contact law's stored energy).
  /// An error, naming step, body and particle, when a particle's position or velocity is not
  /// finite; when the scene's mechanical energy is more than the reference's margin above E0;
  /// or when a particle is faster than that energy could make any item (energy_speed_limit): the
  /// run has gone unstable. Otherwise the report, with a warning when the fastest particle
  /// travels more than kSafeTravel of its diameter per substep.
  Result<MotionReport> check_motion();
  /// Makes the next check_motion take its energy reference anew: after the state was changed in
  /// a way the scene's physics did not do (set_body_velocities, write_state and load_state call
  /// it themselves).
  void rebase_energy() { energy_started_ = false; }
  /// The point the energy guard measures potential energy from (the lowest particle along
  /// gravity when the simulation was created; MotionReport::potential_energy), and the scene's
  /// energy model (motes/energy.h).
  [[nodiscard]] const Eigen::Vector3d& energy_origin() const { return energy_origin_; }
  [[nodiscard]] const EnergyModel& energy_model() const { return energy_model_; }
  /// The neighbour-list skin (m) of a scene whose largest particle diameter is `diameter`:
  /// settings.neighbour_skin, or a tenth of that diameter when it is negative (unset).
  static double neighbour_skin(const Settings& settings, double diameter) {
    return settings.neighbour_skin >= 0.0 ? settings.neighbour_skin : 0.1 * diameter;
  }
  /// Half a particle radius per substep: the scene loader's limit for initial speeds.
  static constexpr double kSafeTravel = 0.25;
  static constexpr std::uint64_t kGuardInterval = 1000;
  /// Reads the neighbour-list figures from the device.
  Result<NeighbourStats> neighbour_stats();

  /// Sets every body's velocity (m/s) and, unless `angular` is empty, angular velocity (rad/s,
  /// world axes), in the scene's body order; the particles' velocities follow. A static body
  /// must get zero, a free sphere (which never turns) a zero angular velocity: anything else is
  /// an error naming the body, and nothing is changed.
  Status set_body_velocities(const std::vector<Eigen::Vector3d>& velocity,
                             const std::vector<Eigen::Vector3d>& angular = {});

  /// Writes a checkpoint (motes/checkpoint.h, docs/reliability.md): the step, the time, and every
  /// device buffer that a later step reads before writing it, as raw bits (particles, bodies,
  /// the soft bodies' last fits, the neighbour lists with the grid of their build; created with
  /// HaloLists, also the partition reference of partition_displacement), with the setup's
  /// fingerprint and `run` (the caller's description of the run). Atomic: the file is
  /// written beside `path` as `path`.tmp, flushed to the disk (fsync), renamed over `path`, and
  /// the directory is flushed; a crash at any moment leaves the old `path` or the new one.
  Status save_state(const std::string& path);
  Status save_state(const std::string& path, const CheckpointRun& run);
  /// Restores a checkpoint written by save_state for the same scene (same sizes and setup
  /// fingerprint), on any backend: stepping on from it on the backend that wrote it gives
  /// bitwise the state the uninterrupted run has at the same step. A missing, truncated, corrupt
  /// (checksum) or foreign file, another format version, or a checkpoint of another scene is
  /// refused with a message naming the file and the reason, and the running state is left
  /// untouched. Version 1 files (bodies and particles only) are still read; the neighbour lists
  /// are then rebuilt at the next step.
  Status load_state(const std::string& path);
  /// Writes a state in the scene's order (as snapshot() gives it: particles' positions and
  /// velocities, rigid bodies' poses and momenta, the soft bodies' fits when their count matches,
  /// the plane contacts' accumulated impulses when given)
  /// as the start of the next step, and sets the step count and time to the state's. The
  /// neighbour lists are kept: they are rebuilt, as in any step, once a particle has moved past
  /// the skin from where the last build saw it. Wrong sizes are an error and change nothing.
  /// Created with HaloLists, the positions written are also the partition reference
  /// (partition_displacement).
  Status write_state(const Snapshot& state);
  /// Halo exchange (created with HaloLists): the send list's state packed on the device and read
  /// into halo_sent(), host memory the device copies to fastest (Device::allocate_host;
  /// shared/halo.h layout). Waits for the queued steps.
  Status halo_pack();
  [[nodiscard]] std::span<const shared::vec4> halo_sent() const {
    return {halo_out_.get(), halo_out_count_};
  }
  /// Where the receive list's state goes, in the same layout, before halo_unpack.
  [[nodiscard]] std::span<shared::vec4> halo_received() { return {halo_in_.get(), halo_in_count_}; }
  /// Writes halo_received() to the device and scatters it there (asks for a list rebuild where a
  /// copy moved past the skin).
  Status halo_unpack();
  /// The same exchange straight between the devices of one host (Device::share_halo_outbox):
  /// the send list's state packed and published in this device's outbox (waits for it), whose
  /// handle share_halo() gives (empty: this device cannot); neighbours open it
  /// (open_peer_halo) and halo_unpack_direct copies each one's part into HaloData and scatters
  /// it. The same bits as the host path.
  [[nodiscard]] Result<std::vector<unsigned char>> share_halo();
  Status halo_pack_direct();
  [[nodiscard]] Result<std::size_t> open_peer_halo(const std::vector<unsigned char>& handle);
  /// One part of the received halo: `count` vec4s from opened outbox `peer` at vec4 `from`, into
  /// the received layout (halo_received()) at vec4 `to`.
  struct HaloFetch {
    std::size_t peer = 0;
    std::size_t from = 0;
    std::size_t to = 0;
    std::size_t count = 0;
  };
  Status halo_unpack_direct(std::span<const HaloFetch> fetches);
  /// Makes the next step rebuild the neighbour lists (the ranks of a run over MPI ranks rebuild
  /// together, when any of them must).
  Status request_rebuild();
  /// Halo entries of the send and receive lists: particles, rigid bodies (HaloLists).
  [[nodiscard]] std::array<std::uint32_t, 4> halo_entries() const { return halo_entries_; }
  /// The largest distance (m) a particle has moved since the last write_state (the ranks'
  /// partition), measured on the device (particles_displacement); infinity when one is not
  /// finite. Created with HaloLists only.
  Result<double> partition_displacement();
  /// Fingerprint (FNV-1a 64) of everything fixed when the simulation was created: sizes, step
  /// parameters, materials, planes, body frames, constraints, clusters, particle radii and
  /// masses. Equal on every backend; a checkpoint loads only where it is equal.
  [[nodiscard]] std::uint64_t setup_hash() const { return setup_hash_; }

  [[nodiscard]] double time() const { return time_; }
  [[nodiscard]] std::uint64_t steps() const { return steps_; }
  [[nodiscard]] const Settings& settings() const { return settings_; }
  [[nodiscard]] std::uint32_t particle_count() const { return sizes_.particles; }
  /// Bodies of the scene (rigid bodies and free spheres), then its cloths and ropes.
  [[nodiscard]] std::uint32_t body_count() const {
    return static_cast<std::uint32_t>(bodies_.size());
  }
  [[nodiscard]] const std::vector<BodyInfo>& bodies() const { return bodies_; }
  /// For each particle on the device (the order of its buffers: rigid bodies' particles first,
  /// then free spheres, soft bodies, cloth and ropes), its index in the scene's particle order
  /// (Snapshot, BodyInfo::first_particle): how a program that reads the device's buffers itself
  /// (motes/vulkan_interop.h) finds a particle's body. A permutation of [0, particle_count()).
  [[nodiscard]] std::vector<std::uint32_t> scene_particle_order() const;
  /// The device's sizes: rigid bodies first (sizes().bodies of them), then the free spheres, then
  /// the cloth and rope particles.
  [[nodiscard]] const Sizes& sizes() const { return sizes_; }
  /// First constraint of each colour (colours + 1 entries; ConstraintColours).
  [[nodiscard]] const std::vector<std::uint32_t>& constraint_colours() const {
    return colour_first_;
  }
  [[nodiscard]] const shared::StepParams& step_params() const { return params_; }
  /// Device memory this simulation holds (Device::required_bytes).
  [[nodiscard]] std::uint64_t device_bytes() const { return device_->required_bytes(sizes_); }
  [[nodiscard]] Device& device() { return *device_; }
  /// The fluids' emitters: their particles on the device and how many have left
  /// (docs/fluids.md, "Emitters").
  [[nodiscard]] const std::vector<EmitterRange>& emitters() const { return emitters_; }
  /// For pictures and output files: the emitters' particles that have not left yet get NaN
  /// centres (they wait far below their nozzles; renderers and readers skip non-finite
  /// particles). Never write such a state back (write_state).
  void hide_parked(Snapshot& state) const;

 private:
  Simulation() = default;
  Status upload(const Scene& scene, const HaloLists* halo);
  /// The rigid bodies' part of a substep with impulse contacts (docs/architecture.md).
  void step_impulses();
  /// One step of position contacts (settings.substeps substeps); lists: the neighbour
  /// update's parameters.
  void step_positions(const shared::StepParams& lists);
  /// Cloth and rope constraints: settings.constraint_iterations sweeps over their colours.
  void relax_constraints();
  /// Cloth and ropes attached to rigid bodies: the bodies take the constraints' pull.
  void absorb_attachments();
  /// The fluids' density constraint in a substep of step_positions (docs/fluids.md, "The
  /// substep", 5): settings.fluid_iterations Jacobi sweeps; with dynamic rigid bodies each takes
  /// its particles' reactions to the liquid (`bodies`).
  void relax_fluids(bool bodies);
  /// Impulse contacts: every contact's accumulated impulse to zero and its list slots void (a
  /// new state has no contact history to warm-start from).
  Status clear_contact_history();
  /// Writes a scene-ordered state (a snapshot or a checkpoint's) to the device and, with
  /// `rebuild`, asks for a neighbour-list rebuild and clears the impulse contacts' history.
  Status restore(const Snapshot& state, bool rebuild = true);
  /// The emitters' particles due by the start of the step at time_ leave their nozzles: their
  /// places and velocities written on the device (Device::write_at: their range of ParticlePos
  /// and ParticleVel), a list rebuild asked for, their energy added to the energy guard's
  /// reference.
  Status emit();
  /// Each emitter's particles that have left (inverse mass > 0 on the device), after a state
  /// was written from outside.
  Status count_emitted();
  /// The scene body and scene particle index of device particle i.
  [[nodiscard]] std::pair<std::uint32_t, std::uint32_t> locate_particle(std::uint32_t i) const;
  /// load_state for a version 1 file (bytes: the whole file).
  Status load_state_v1(const std::string& path, const std::vector<unsigned char>& bytes);

  std::unique_ptr<Device> device_;
  Settings settings_;
  Sizes sizes_;
  shared::StepParams params_{};
  std::vector<BodyInfo> bodies_;
  /// Per scene body: its index among the device's rigid bodies, or for a free sphere the index of
  /// its particle on the device (the rigid bodies' particles come first); for a cloth or rope its
  /// first particle on the device.
  std::vector<std::uint32_t> device_index_;
  /// BodyFirst as uploaded (B + 1 entries): the first device particle of each rigid body.
  std::vector<std::uint32_t> rigid_first_;
  /// BodyInvInertia as uploaded (B entries): inverse principal moments of each rigid body.
  std::vector<shared::vec4> rigid_inv_inertia_;
  /// Constraints of colour c are Constraints [colour_first_[c], colour_first_[c + 1]).
  std::vector<std::uint32_t> colour_first_;
  /// At most this many constraints are relaxed in one launch (constraints_relax); more go a launch
  /// per colour (constraints_solve). DeviceInfo::one_launch_constraints, or
  /// MOTES_CONSTRAINTS_RELAX_LIMIT.
  std::uint64_t relax_limit_ = 0;
  std::vector<EmitterRange> emitters_;
  /// Position contacts: the scene has dynamic rigid bodies (their passes run).
  bool position_bodies_ = false;
  /// A fluid's material has adhesion: fluid_velocity gives the solids its reaction.
  bool fluid_adhesion_ = false;
  /// (scene body, orientation) of the free spheres that are not at the identity orientation; a
  /// free sphere never turns.
  std::vector<std::pair<std::uint32_t, shared::vec4>> sphere_turns_;
  /// HaloLists as halo entries (send particles, send bodies, receive particles, receive bodies);
  /// their device indices are HaloIndex.
  std::array<std::uint32_t, 4> halo_entries_{};
  /// Host memory of the packed halo, sent and received (Device::allocate_host), freed through the
  /// device (before take_device hands it on).
  /// Queue halo_pack of the send list and halo_unpack of the receive list (HaloData from word 0).
  void queue_halo_pack();
  void queue_halo_unpack();
  HostMemory<shared::vec4> halo_out_, halo_in_;
  std::size_t halo_out_count_ = 0;
  std::size_t halo_in_count_ = 0;
  /// setup_hash(), and the FNV-1a 64 of the particles' radii and inverse masses (the w of
  /// ParticlePos and ParticleVel, device order), which a checkpoint's particles must match.
  std::uint64_t setup_hash_ = 0;
  std::uint64_t particle_w_hash_ = 0;
  /// The energy guard: the scene's energy model (motes/energy.h), the reference point that
  /// potential energy is measured from (the lowest particle at upload; EnergyPartials' header),
  /// each device rigid body's scene body, and check_motion's reference and largest rise since.
  EnergyModel energy_model_;
  Eigen::Vector3d energy_origin_ = Eigen::Vector3d::Zero();
  std::vector<std::uint32_t> rigid_scene_body_;
  bool energy_started_ = false;
  EnergyReference energy_reference_;
  double largest_rise_ = 0.0;
  /// The device's energy (EnergyPartials summed in double): the item index is the device's.
  struct DeviceEnergy {
    double kinetic = 0.0;
    double potential = 0.0;
    double largest_kinetic = 0.0;
    std::uint32_t largest_item = 0xFFFFFFFFu;
  };
  Result<DeviceEnergy> read_energy();
  /// The scene body and particle (MechanicalEnergy::kNone for a rigid body) of energy item j.
  [[nodiscard]] std::pair<std::uint32_t, std::uint32_t> locate_item(std::uint32_t j) const;
  double time_ = 0.0;
  std::uint64_t steps_ = 0;
};

}  // namespace motes
MOTES_API_END
