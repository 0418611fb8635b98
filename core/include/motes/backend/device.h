// The backend interface: a Device owns the simulation's buffers and implements each kernel family
// with the same contract on every backend (docs/architecture.md). The core owns the step and calls
// these in order; backends never see a Scene.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "motes/api.h"
#include "motes/backend/kernels.h"
#include "motes/status.h"
#include "shared/params.h"

MOTES_API_BEGIN
namespace motes {

/// Every buffer a device holds, grouped by feature (checkpoints name buffers by buffer_name, so the
/// order is free). Element types and counts: see buffer_layout().
enum class Buffer : std::uint32_t {
  // Particles (N). The rigid bodies' particles come first, in body order: body b owns particles
  // [BodyFirst[b], BodyFirst[b+1]) and BodyFirst[B] = Nr. Particles [Nr, N) are free spheres
  // (one-particle bodies without spin): no body state, integrated as particles.
  ParticlePos,       ///< vec4: world position xyz, w = radius
  ParticleVel,       ///< vec4: world velocity xyz, w = inverse mass (0 for static bodies)
  ParticleLocal,     ///< vec4 (Nr): offset from the body's centre of mass in the body frame
  ParticleBody,      ///< uint: body index (B + k for the k-th free sphere: unique)
  ParticleMaterial,  ///< uint: material index
  ParticleForce,     ///< vec4: contact force (output of contacts_compute)
  // Rigid bodies (B).
  BodyPos,         ///< vec4: centre of mass xyz, w = inverse mass (0 = static)
  BodyQuat,        ///< vec4: orientation (x, y, z, w), body (principal) frame to world
  BodyVel,         ///< vec4: linear velocity
  BodyAngMom,      ///< vec4: angular momentum (world)
  BodyAngVel,      ///< vec4: angular velocity (world)
  BodyInvInertia,  ///< vec4: inverse principal moments of inertia (body frame)
  BodyForce,       ///< vec4: summed contact force (output of bodies_reduce)
  BodyTorque,      ///< vec4: summed torque about the centre of mass
  BodyFirst,       ///< uint (B + 1): first particle of each body, then Nr
  // Hashed grid (outputs of grid_build).
  GridBucket,     ///< uint (N): bucket of particle i
  GridOrder,      ///< uint (N): particle ids sorted stably by bucket
  GridCellStart,  ///< uint (T + 1): sorted position of each bucket's first particle, then N
  SortedPos,      ///< vec4 (N): ParticlePos in grid order
  SortedBody,     ///< uint (N): ParticleBody in grid order
  // Neighbour lists (outputs of neighbours_build).
  NeighbourList,    ///< uint (K * N): entry k of particle i at k * N + i, a particle id
  NeighbourCount,   ///< uint (N): neighbours found at the last build (may exceed K)
  NeighbourRefPos,  ///< vec4 (N): ParticlePos at the last build
  NeighbourState,   ///< uint (4): MOTES_NEIGHBOUR_* words (shared/neighbours.h)
  // Tables.
  ContactLaws,  ///< ContactLaw (M * M): law of material pair (a, b) at a * M + b
  Planes,       ///< PlaneData (P)
  // Cloth and ropes: their particles are [Nl, N) (StepParams.linked_first).
  Constraints,  ///< Constraint (C): distance constraints, grouped by colour (shared/links.h)
  /// uint (colours + 1 with constraints, else 0): each colour's first constraint in Constraints,
  /// then C (constraints_relax reads it; constraints_solve takes its range in StepParams).
  ConstraintColours,
  /// uint (N - Nl + 1 + E; empty without a cloth from a triangle mesh): for each linked particle,
  /// where its list of the particles within two links starts, then the lists, ascending
  /// (shared/links.h, contact_listed).
  LinkExclusions,
  // Soft bodies (shape matching): their particles are [Ns, Nl) (StepParams.soft_first).
  Clusters,        ///< Cluster (S): clusters of soft-body particles (shared/shape_matching.h)
  ClusterMembers,  ///< ClusterMember (Sm): every cluster's members, cluster by cluster
  ClusterFrames,   ///< ClusterFrame (S): the last fit; its rotation starts the next one
  /// uint (Ns + 1 + Sm): soft particle Ns + k is in the members ClusterGather[j] for j in
  /// [ClusterGather[k], ClusterGather[k + 1]) (the offsets count from the buffer's start).
  ClusterGather,
  // Impulse contacts (StepParams.flags MOTES_FLAG_IMPULSE; empty otherwise): rigid bodies only.
  ParticleMoment,   ///< vec4 (Nr): impulses_compute's (or the absorb's) moment about the centre
  BodyVelStart,     ///< vec4 (B): BodyVel at the start of the impulse stage, w = contacts
  BodyAngVelStart,  ///< vec4 (B): BodyAngVel at the start of the impulse stage
  BodyVelPush,      ///< vec4 (B): BodyVel after the impulse sweeps with position correction
  BodyAngMomPush,   ///< vec4 (B): BodyAngMom after the impulse sweeps with position correction
  /// vec4 ((K + P) x Nr): accumulated impulse of every contact of rigid particle i (xyz: on the
  /// lower particle id's body, w: its normal part), its list slot k at k * Nr + i, plane k at
  /// (K + k) * Nr + i. Kept across substeps while the lists stay (warm start).
  ContactImpulse,
  /// uint (Nr): NeighbourState[MOTES_NEIGHBOUR_BUILDS] when particle i's list slots of
  /// ContactImpulse were last written; another value: the lists were rebuilt, the slots are void.
  ImpulseStamp,
  // Run-time checks (not saved in checkpoints).
  MotionCheck,  ///< uint (4): particles_check's MOTES_MOTION_* words (shared/motion_check.h)
  /// uint (4 + 4 x blocks of 256 items, shared/energy.h): the reference point x_ref that
  /// potential energy is measured from (written by the host), then per block of energy_reduce's
  /// items its kinetic and potential energy, its largest item kinetic energy and that item.
  EnergyPartials,
  // Runs over MPI ranks (motes/distributed.h, docs/scale-out.md; empty in one process).
  /// uint (Sizes::halo_index): the entries halo_pack and halo_unpack walk, as StepParams
  /// halo_first, halo_particles and halo_bodies say: particle indices, then rigid body indices.
  HaloIndex,
  /// vec4 (Sizes::halo_data): the packed state of halo entries (shared/halo.h: particle entry k
  /// at 2k (position) and 2k + 1 (velocity), rigid body entry j at 2 P + 5 j + 0..4).
  HaloData,
  /// vec4 (N when Sizes::partition, else 0): ParticlePos when the ranks last partitioned the
  /// scene; particles_displacement measures from it.
  PartitionRefPos,
  /// uint (1 when Sizes::partition, else 0): particles_displacement's word (shared/halo.h).
  PartitionCheck,
  /// vec4 (as ContactImpulse): the accumulated impulses of a substep's correcting sweeps
  /// (MOTES_FLAG_IMPULSE_SPLIT), which start from the relaxed ones; written before it is read in
  /// every substep (not in checkpoints).
  ContactImpulseSplit,
  /// vec4 (B with impulse contacts, else 0): xyz, the part of each body's centre of mass below
  /// BodyPos's rounding: the impulse stage's poses move the centre as this pair of floats
  /// (shared/body_math.h: body_push_pose), so that a body far from the origin moves by less than
  /// the spacing of floats there. w: 0.
  BodyPosLow,
  // Fluids (docs/fluids.md): their particles are [Nf, Nf + Sizes::fluid_particles)
  // (StepParams.fluid_first, fluid_count); empty without fluid.
  /// vec4 (fluid particles): fluid_density's rho_i, lambda_i of the last sweep, Lambda_i (the
  /// substep's sum of lambda_i, for the pressure), 0.
  FluidState,
  /// FluidMaterial (M with fluid, else 0): each material's fluid parameters (shared/fluid.h;
  /// 0 for a material no fluid uses), written once by the host (motes/fluid.h).
  FluidMaterials,
  /// vec4 (fluid particles): fluid_vorticity's copy of each fluid particle's velocity, 0: the
  /// velocity pass (fluid_velocity) reads its own and its neighbours' from here, never from the
  /// ParticleVel it writes.
  FluidVelOld,
  /// vec4 (fluid particles): fluid_vorticity's omega_i (the SPH curl of the velocity), |omega_i|.
  FluidAux,
  /// vec4 (fluid particles): fluid_vorticity's n_i (Akinci et al. 2013's surface normal), 0.
  FluidNormal,
  Count
};

/// Kernel families, in the order a step runs them (motes/backend/kernels.h names each once, with
/// its contract and the buffers it reads and writes).
enum class Kernel : std::uint32_t {
#define MOTES_KERNEL_ENUMERATOR(E, name, reads, writes) E,
  MOTES_KERNELS(MOTES_KERNEL_ENUMERATOR)
#undef MOTES_KERNEL_ENUMERATOR
      Count
};

constexpr std::size_t kBufferCount = static_cast<std::size_t>(Buffer::Count);
constexpr std::size_t kKernelCount = static_cast<std::size_t>(Kernel::Count);

const char* buffer_name(Buffer b);
/// The buffer called `name` (buffer_name), or Buffer::Count.
Buffer buffer_from_name(std::string_view name);
/// The family's name, e.g. "constraints_solve".
const char* kernel_name(Kernel k);
/// The family called `name` (kernel_name), or Kernel::Count.
Kernel kernel_from_name(std::string_view name);

/// A set of buffers: bit b is Buffer b.
using BufferMask = std::uint64_t;
static_assert(kBufferCount <= 64, "BufferMask holds one bit per buffer");
[[nodiscard]] constexpr BufferMask buffer_bit(Buffer b) {
  return BufferMask{1} << static_cast<std::uint32_t>(b);
}
/// The buffers family k reads, and those it writes (motes/backend/kernels.h).
BufferMask kernel_reads(Kernel k);
BufferMask kernel_writes(Kernel k);

/// Element counts of a simulation.
struct Sizes {
  std::uint32_t particles = 0;           ///< N
  std::uint32_t rigid_particles = 0;     ///< Nr <= N: the rigid bodies' particles come first
  std::uint32_t bodies = 0;              ///< B: rigid bodies
  std::uint32_t table = 0;               ///< T, a power of two >= 64
  std::uint32_t materials = 0;           ///< M
  std::uint32_t planes = 0;              ///< P
  std::uint32_t neighbour_capacity = 0;  ///< K: list entries per particle
  std::uint32_t constraints = 0;         ///< C: distance constraints of cloth and ropes
  std::uint32_t soft_particles = 0;      ///< Ns: particles of soft bodies
  std::uint32_t clusters = 0;            ///< S: shape-matching clusters
  std::uint32_t cluster_members = 0;     ///< Sm: their members (a particle may be in several)
  std::uint32_t impulse = 0;             ///< 1: rigid contacts by impulses (buffers for them)
  std::uint32_t absorb = 0;  ///< 1: cloth or ropes attached to rigid bodies (ParticleMoment)
  std::uint32_t link_exclusions = 0;  ///< words of LinkExclusions: 0 without a mesh cloth
  // Runs over MPI ranks (0 in one process): see HaloIndex, HaloData, PartitionRefPos.
  std::uint32_t halo_index = 0;       ///< words of HaloIndex
  std::uint32_t halo_data = 0;        ///< vec4s of HaloData
  std::uint32_t partition = 0;        ///< 1: PartitionRefPos (N) and PartitionCheck (1) exist
  std::uint32_t fluid_particles = 0;  ///< particles of fluids (FluidState, FluidVelOld, FluidAux,
                                      ///< FluidNormal; FluidMaterials when > 0)
  /// The constraints' colours (ConstraintColours has one more word); after the fields the setup
  /// hash covers (the colouring itself is hashed with the layout).
  std::uint32_t constraint_colours = 0;
};

/// Bytes of one element and number of elements of a buffer.
struct BufferLayout {
  std::size_t element_bytes = 0;
  std::size_t count = 0;
  [[nodiscard]] std::size_t bytes() const { return element_bytes * count; }
};
BufferLayout buffer_layout(Buffer b, const Sizes& sizes);
/// Sum of buffer_layout(b).bytes() over every buffer.
std::uint64_t buffers_bytes(const Sizes& sizes);

/// Hash-table size the core uses for n particles: the power of two >= 4n, at least 64.
std::uint32_t grid_table_size(std::uint32_t particles);

/// `sizes` for `particles` particles in the same proportions: rigid particles, bodies, soft and
/// fluid particles, constraints, clusters and their members, and the mesh-cloth exclusion lists
/// scaled with N (rounded down), materials, planes and the neighbour capacity kept, the table
/// grid_table_size(particles). What "the largest particle count that fits" is counted in.
Sizes scale_sizes(const Sizes& sizes, std::uint32_t particles);

/// One buffer a device would allocate: its name and bytes.
struct BufferSize {
  std::string name;
  std::uint64_t bytes = 0;
};

/// The most bytes one buffer may hold on a device, and the limit's name for messages
/// ("maxStorageBufferRange"); UINT64_MAX and "" where only memory limits a buffer.
struct BufferLimit {
  std::uint64_t bytes = UINT64_MAX;
  std::string what;
};

class Device;

/// What a simulation of some sizes needs from a device, and what the device has.
struct DeviceFit {
  std::uint64_t need = 0;  ///< Device::required_bytes
  std::uint64_t have = 0;  ///< Device::available_bytes (or the value given)
  BufferSize largest;      ///< Device::largest_buffer
  BufferLimit limit;       ///< Device::buffer_limit
  [[nodiscard]] bool memory_fits() const { return need <= have; }
  [[nodiscard]] bool buffers_fit() const { return largest.bytes <= limit.bytes; }
  [[nodiscard]] bool fits() const { return memory_fits() && buffers_fit(); }
};
/// The device's numbers for these sizes, with `have` bytes available.
DeviceFit device_fit(const Device& device, const Sizes& sizes, std::uint64_t have);
/// The largest particle count n <= sizes.particles for which scale_sizes(sizes, n) fits in `have`
/// bytes and under the device's buffer limit (bisection; 0 when not even one particle fits).
std::uint32_t largest_fitting_particles(const Device& device, const Sizes& sizes,
                                        std::uint64_t have);
/// Ok when these sizes fit on the device (Device::available_bytes, read once); otherwise an error
/// with what is needed, what the device has, and the largest particle count that fits
/// (largest_fitting_particles). Simulation::create calls it before it allocates anything.
Status check_device_fits(const Device& device, const Sizes& sizes);

/// Time spent per kernel family since the last reset (seconds) and launch counts.
struct KernelTimes {
  std::array<double, kKernelCount> seconds{};
  std::array<std::uint64_t, kKernelCount> launches{};
};

/// Why a call of a family of runs over MPI ranks (halo_pack, halo_unpack,
/// particles_displacement) with these parameters would reach outside buffers allocated for
/// `sizes`: halo entries beyond HaloIndex or HaloData, particles or bodies beyond theirs, no
/// partition buffers; "" when it stays inside, and for every other family. The GPU backends
/// refuse such a call before anything runs (their first error, sticky).
std::string halo_launch_error(Kernel k, const shared::StepParams& p, const Sizes& sizes);
/// Why an energy_reduce with these parameters would write blocks beyond EnergyPartials allocated
/// for `sizes` (more items than the allocation's: shared/energy.h); "" when it stays inside, and
/// for every other family. Every backend refuses such a call (the GPUs with their first error).
std::string energy_launch_error(Kernel k, const shared::StepParams& p, const Sizes& sizes);

/// One device of one backend, as listed by `motes devices`.
struct DeviceInfo {
  std::string backend;  ///< "openmp", "cuda", "vulkan"
  int index = 0;        ///< index within the backend
  std::string name;     ///< e.g. CPU model, GPU name
  std::string detail;   ///< threads, driver, memory, subgroup size...
  /// The most cloth and rope constraints the core relaxes in one launch on this device
  /// (constraints_relax, one workgroup); a scene with more takes a launch per colour and sweep
  /// (constraints_solve). On an H200 one workgroup beats a launch per colour up to about 12,000
  /// constraints (CUDA) and 13,700 (Vulkan), docs/benchmarks.md; lavapipe runs one workgroup
  /// slower than the launches (0). MOTES_CONSTRAINTS_RELAX_LIMIT=C overrides it.
  std::uint64_t one_launch_constraints = 8192;
};

/// A backend device. Kernels are enqueued in order; errors surface at synchronize().
class Device {
 public:
  Device() = default;
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;
  virtual ~Device() = default;

  [[nodiscard]] virtual const DeviceInfo& info() const = 0;

  /// Bytes this device would hold for these sizes: every buffer plus the backend's own scratch
  /// (sort storage, guard words). The core compares it with available_bytes() before allocating.
  [[nodiscard]] virtual std::uint64_t required_bytes(const Sizes& sizes) const = 0;
  /// Memory the device can still give (GPU free memory, or the host's available memory).
  [[nodiscard]] virtual std::uint64_t available_bytes() const = 0;
  /// The largest single buffer this device would allocate for these sizes (each buffer is one
  /// allocation, bound whole). Default: the largest buffer_layout().
  [[nodiscard]] virtual BufferSize largest_buffer(const Sizes& sizes) const;
  /// The most bytes one buffer may hold (Vulkan: maxStorageBufferRange and
  /// maxMemoryAllocationSize). Default: no limit but memory.
  [[nodiscard]] virtual BufferLimit buffer_limit() const { return {}; }
  /// (Re)allocates every buffer for these sizes; contents are undefined afterwards.
  virtual Status allocate(const Sizes& sizes) = 0;
  /// Copies host memory into the start of a buffer; bytes <= buffer_layout(b).bytes().
  virtual Status write(Buffer b, const void* src, std::size_t bytes) = 0;
  /// Copies host memory into bytes [offset, offset + bytes) of a buffer, leaving the rest as it
  /// is (an emitter's new particles, docs/fluids.md "Emitters"). The default reads the buffer up to
  /// there, patches it and writes it back; the backends copy only the range.
  virtual Status write_at(Buffer b, std::size_t offset, const void* src, std::size_t bytes);
  /// Copies the start of a buffer to host memory (waits for queued kernels).
  virtual Status read(Buffer b, void* dst, std::size_t bytes) = 0;

  /// Queues one call of kernel family k with these parameters (motes/backend/kernels.h: what each
  /// family computes, reads and writes). Kernels run in the order they are queued; an error
  /// (parameters beyond the allocated buffers) surfaces at synchronize().
  virtual void enqueue(Kernel k, const shared::StepParams& p) = 0;
  /// Whether this device runs family k (every backend runs every family today).
  [[nodiscard]] virtual bool supports(Kernel k) const { return k != Kernel::Count; }

  /// Waits for queued work; reports any error it raised.
  virtual Status synchronize() = 0;

  /// Every buffer is followed by guard words that no kernel may touch: fails, naming the buffer,
  /// when one was overwritten (the conformance suite calls this after every case).
  virtual Status check_guards() = 0;

  /// Host memory that read() and write() copy to and from fastest, for what crosses between host
  /// and device every step (the halo of a run over MPI ranks): page-locked on CUDA (a DMA
  /// transfer instead of a staged one); ordinary aligned memory by default. Freed by
  /// free_host(); nullptr when none can be had.
  [[nodiscard]] virtual void* allocate_host(std::size_t bytes);
  virtual void free_host(void* memory);

  /// Device-direct halo exchange between the processes of one host (a run over MPI ranks,
  /// docs/scale-out.md): each device keeps an *outbox*, device memory other processes' devices
  /// can read, which publish_halo_outbox fills from HaloData after halo_pack; a neighbour opens
  /// it by its handle and copies its part straight into its own HaloData before halo_unpack.
  /// The default (OpenMP, Vulkan): no outbox, and the halo goes through host memory and MPI.
  ///
  /// An outbox of at least `bytes` (kept, or grown, for the device's life) and the handle another
  /// process opens it by; an empty handle when this device cannot share memory that way.
  [[nodiscard]] virtual Result<std::vector<unsigned char>> share_halo_outbox(std::size_t bytes);
  /// Queues a copy of HaloData's first `bytes` into the outbox, after the queued kernels.
  virtual Status publish_halo_outbox(std::size_t bytes);
  /// Opens another process's outbox by its handle (share_halo_outbox there); its index for
  /// fetch_peer_outbox. A failure changes nothing else (the caller falls back to host memory).
  [[nodiscard]] virtual Result<std::size_t> open_peer_outbox(
      const std::vector<unsigned char>& handle);
  /// Queues a copy of `bytes` from opened outbox `peer` at byte `from` into HaloData at byte
  /// `to`, after the queued kernels and before the ones queued next.
  virtual Status fetch_peer_outbox(std::size_t peer, std::size_t from, std::size_t to,
                                   std::size_t bytes);
  /// Closes every opened outbox (waits for the queued copies first). Before an outbox is grown,
  /// every process that opened it must have closed it (DistributedSimulation agrees on that).
  virtual void close_peer_outboxes() {}

  /// Per-kernel timing (may cost a synchronization per kernel while on).
  virtual void set_timing(bool on) = 0;
  [[nodiscard]] virtual KernelTimes kernel_times() const = 0;
  virtual void reset_kernel_times() = 0;
};

/// Frees Device::allocate_host memory through the device that gave it.
struct HostFree {
  Device* device = nullptr;
  void operator()(void* memory) const {
    if (device != nullptr) device->free_host(memory);
  }
};
template <typename T>
using HostMemory = std::unique_ptr<T, HostFree>;

}  // namespace motes
MOTES_API_END
