// Names and layouts of the backend interface's buffers and kernels.
#include "motes/backend/device.h"

#include <fmt/format.h>

#include <cstring>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <new>
#include <vector>

#include "shared/energy.h"
#include "shared/fluid.h"
#include "shared/halo.h"
#include "shared/links.h"
#include "shared/shape_matching.h"

namespace motes {

const char* buffer_name(Buffer b) {
  switch (b) {
    case Buffer::ParticlePos:
      return "ParticlePos";
    case Buffer::ParticleVel:
      return "ParticleVel";
    case Buffer::ParticleLocal:
      return "ParticleLocal";
    case Buffer::ParticleBody:
      return "ParticleBody";
    case Buffer::ParticleMaterial:
      return "ParticleMaterial";
    case Buffer::ParticleForce:
      return "ParticleForce";
    case Buffer::BodyPos:
      return "BodyPos";
    case Buffer::BodyQuat:
      return "BodyQuat";
    case Buffer::BodyVel:
      return "BodyVel";
    case Buffer::BodyAngMom:
      return "BodyAngMom";
    case Buffer::BodyAngVel:
      return "BodyAngVel";
    case Buffer::BodyInvInertia:
      return "BodyInvInertia";
    case Buffer::BodyForce:
      return "BodyForce";
    case Buffer::BodyTorque:
      return "BodyTorque";
    case Buffer::BodyFirst:
      return "BodyFirst";
    case Buffer::GridBucket:
      return "GridBucket";
    case Buffer::GridOrder:
      return "GridOrder";
    case Buffer::GridCellStart:
      return "GridCellStart";
    case Buffer::SortedPos:
      return "SortedPos";
    case Buffer::SortedBody:
      return "SortedBody";
    case Buffer::NeighbourList:
      return "NeighbourList";
    case Buffer::NeighbourCount:
      return "NeighbourCount";
    case Buffer::NeighbourRefPos:
      return "NeighbourRefPos";
    case Buffer::NeighbourState:
      return "NeighbourState";
    case Buffer::ContactLaws:
      return "ContactLaws";
    case Buffer::Planes:
      return "Planes";
    case Buffer::Constraints:
      return "Constraints";
    case Buffer::ConstraintColours:
      return "ConstraintColours";
    case Buffer::Clusters:
      return "Clusters";
    case Buffer::ClusterMembers:
      return "ClusterMembers";
    case Buffer::ClusterFrames:
      return "ClusterFrames";
    case Buffer::ClusterGather:
      return "ClusterGather";
    case Buffer::ParticleMoment:
      return "ParticleMoment";
    case Buffer::BodyVelStart:
      return "BodyVelStart";
    case Buffer::BodyAngVelStart:
      return "BodyAngVelStart";
    case Buffer::ContactImpulse:
      return "ContactImpulse";
    case Buffer::ContactImpulseSplit:
      return "ContactImpulseSplit";
    case Buffer::BodyPosLow:
      return "BodyPosLow";
    case Buffer::FluidState:
      return "FluidState";
    case Buffer::FluidMaterials:
      return "FluidMaterials";
    case Buffer::FluidVelOld:
      return "FluidVelOld";
    case Buffer::FluidAux:
      return "FluidAux";
    case Buffer::FluidNormal:
      return "FluidNormal";
    case Buffer::ImpulseStamp:
      return "ImpulseStamp";
    case Buffer::MotionCheck:
      return "MotionCheck";
    case Buffer::LinkExclusions:
      return "LinkExclusions";
    case Buffer::HaloIndex:
      return "HaloIndex";
    case Buffer::HaloData:
      return "HaloData";
    case Buffer::PartitionRefPos:
      return "PartitionRefPos";
    case Buffer::PartitionCheck:
      return "PartitionCheck";
    case Buffer::BodyVelPush:
      return "BodyVelPush";
    case Buffer::BodyAngMomPush:
      return "BodyAngMomPush";
    case Buffer::EnergyPartials:
      return "EnergyPartials";
    case Buffer::Count:
      break;
  }
  return "?";
}

namespace {

using enum Buffer;

constexpr BufferMask mask_of(std::initializer_list<Buffer> buffers) {
  BufferMask m = 0;
  for (Buffer b : buffers) m |= buffer_bit(b);
  return m;
}

struct KernelEntry {
  const char* name;
  BufferMask reads, writes;
};

// One entry per family, from the list in motes/backend/kernels.h.
#define MOTES_KERNEL_ENTRY(E, name, reads, writes) \
  KernelEntry{#name, mask_of({MOTES_UNPAREN reads}), mask_of({MOTES_UNPAREN writes})},
#define MOTES_UNPAREN(...) __VA_ARGS__
constexpr std::array<KernelEntry, kKernelCount> kKernels{{MOTES_KERNELS(MOTES_KERNEL_ENTRY)}};
#undef MOTES_UNPAREN
#undef MOTES_KERNEL_ENTRY

}  // namespace

const char* kernel_name(Kernel k) {
  const auto i = static_cast<std::size_t>(k);
  return i < kKernelCount ? kKernels[i].name : "?";
}

Kernel kernel_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kKernelCount; ++i) {
    if (name == kKernels[i].name) return static_cast<Kernel>(i);
  }
  return Kernel::Count;
}

BufferMask kernel_reads(Kernel k) {
  const auto i = static_cast<std::size_t>(k);
  return i < kKernelCount ? kKernels[i].reads : 0;
}

BufferMask kernel_writes(Kernel k) {
  const auto i = static_cast<std::size_t>(k);
  return i < kKernelCount ? kKernels[i].writes : 0;
}

Buffer buffer_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kBufferCount; ++i) {
    if (name == buffer_name(static_cast<Buffer>(i))) return static_cast<Buffer>(i);
  }
  return Buffer::Count;
}

BufferLayout buffer_layout(Buffer b, const Sizes& s) {
  constexpr std::size_t kVec4 = 16;
  constexpr std::size_t kUint = 4;
  switch (b) {
    case Buffer::ParticlePos:
    case Buffer::ParticleVel:
    case Buffer::ParticleForce:
    case Buffer::SortedPos:
    case Buffer::NeighbourRefPos:
      return {kVec4, s.particles};
    case Buffer::ParticleLocal:
      return {kVec4, s.rigid_particles};
    case Buffer::ParticleBody:
    case Buffer::ParticleMaterial:
    case Buffer::GridBucket:
    case Buffer::GridOrder:
    case Buffer::SortedBody:
    case Buffer::NeighbourCount:
      return {kUint, s.particles};
    case Buffer::NeighbourList:
      return {kUint, std::size_t{s.neighbour_capacity} * s.particles};
    case Buffer::NeighbourState:
    case Buffer::MotionCheck:
      return {kUint, 4};
    case Buffer::BodyPos:
    case Buffer::BodyQuat:
    case Buffer::BodyVel:
    case Buffer::BodyAngMom:
    case Buffer::BodyAngVel:
    case Buffer::BodyInvInertia:
    case Buffer::BodyForce:
    case Buffer::BodyTorque:
      return {kVec4, s.bodies};
    case Buffer::BodyFirst:
      return {kUint, std::size_t{s.bodies} + 1};
    case Buffer::GridCellStart:
      return {kUint, std::size_t{s.table} + 1};
    case Buffer::ContactLaws:
      return {sizeof(shared::ContactLaw), std::size_t{s.materials} * s.materials};
    case Buffer::Planes:
      return {sizeof(shared::PlaneData), s.planes};
    case Buffer::Constraints:
      return {sizeof(shared::Constraint), s.constraints};
    case Buffer::ConstraintColours:
      return {kUint, s.constraints > 0 ? std::size_t{s.constraint_colours} + 1 : 0};
    case Buffer::Clusters:
      return {sizeof(shared::Cluster), s.clusters};
    case Buffer::ClusterMembers:
      return {sizeof(shared::ClusterMember), s.cluster_members};
    case Buffer::ClusterFrames:
      return {sizeof(shared::ClusterFrame), s.clusters};
    case Buffer::ClusterGather:
      return {kUint, s.clusters > 0 ? std::size_t{s.soft_particles} + 1 + s.cluster_members : 0};
    case Buffer::ParticleMoment:
      return {kVec4, s.impulse != 0 || s.absorb != 0 ? std::size_t{s.rigid_particles} : 0};
    case Buffer::BodyVelStart:
    case Buffer::BodyAngVelStart:
    case Buffer::BodyVelPush:
    case Buffer::BodyAngMomPush:
    case Buffer::BodyPosLow:
      return {kVec4, s.impulse != 0 ? std::size_t{s.bodies} : 0};
    case Buffer::ContactImpulse:
    case Buffer::ContactImpulseSplit:
      return {kVec4, s.impulse != 0 ? (std::size_t{s.neighbour_capacity} + s.planes) *
                                          std::size_t{s.rigid_particles}
                                    : 0};
    case Buffer::ImpulseStamp:
      return {kUint, s.impulse != 0 ? std::size_t{s.rigid_particles} : 0};
    case Buffer::LinkExclusions:
      return {kUint, s.link_exclusions};
    case Buffer::HaloIndex:
      return {kUint, s.halo_index};
    case Buffer::HaloData:
      return {kVec4, s.halo_data};
    case Buffer::PartitionRefPos:
      return {kVec4, s.partition != 0 ? std::size_t{s.particles} : 0};
    case Buffer::PartitionCheck:
      return {kUint, s.partition != 0 ? std::size_t{1} : 0};
    case Buffer::FluidState:
    case Buffer::FluidVelOld:
    case Buffer::FluidAux:
    case Buffer::FluidNormal:
      return {kVec4, s.fluid_particles};
    case Buffer::FluidMaterials:
      return {sizeof(shared::FluidMaterial), s.fluid_particles > 0 ? std::size_t{s.materials} : 0};
    case Buffer::EnergyPartials:
      return {kUint, MOTES_ENERGY_HEADER +
                         std::size_t{MOTES_ENERGY_WORDS} *
                             shared::energy_blocks(shared::energy_items(
                                 s.bodies, s.particles, std::min(s.rigid_particles, s.particles)))};
    case Buffer::Count:
      break;
  }
  return {};
}

std::uint64_t buffers_bytes(const Sizes& sizes) {
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < kBufferCount; ++i) {
    total += buffer_layout(static_cast<Buffer>(i), sizes).bytes();
  }
  return total;
}

std::uint32_t grid_table_size(std::uint32_t particles) {
  const std::uint64_t want = std::uint64_t{particles} * 4;
  std::uint64_t t = std::bit_ceil(want < 64 ? std::uint64_t{64} : want);
  if (t > (std::uint64_t{1} << 31)) t = std::uint64_t{1} << 31;
  return static_cast<std::uint32_t>(t);
}

Sizes scale_sizes(const Sizes& sizes, std::uint32_t particles) {
  const std::uint64_t from = sizes.particles;
  const auto scale = [&](std::uint32_t count) -> std::uint32_t {
    if (from == 0) return 0;
    // count <= 2^32 and particles < 2^32: the product fits in 64 bits.
    return static_cast<std::uint32_t>(std::uint64_t{count} * particles / from);
  };
  Sizes s = sizes;
  s.particles = particles;
  s.rigid_particles = scale(sizes.rigid_particles);
  s.bodies = scale(sizes.bodies);
  s.soft_particles = scale(sizes.soft_particles);
  s.fluid_particles = scale(sizes.fluid_particles);
  s.constraints = scale(sizes.constraints);
  s.clusters = scale(sizes.clusters);
  s.cluster_members = scale(sizes.cluster_members);
  s.link_exclusions = scale(sizes.link_exclusions);
  s.halo_index = scale(sizes.halo_index);
  s.halo_data = scale(sizes.halo_data);
  s.table = grid_table_size(particles);
  return s;
}

std::string halo_launch_error(Kernel k, const shared::StepParams& p, const Sizes& sizes) {
  if (k != Kernel::HaloPack && k != Kernel::HaloUnpack && k != Kernel::ParticlesDisplacement) {
    return {};
  }
  if (p.particle_count > sizes.particles || p.body_count > sizes.bodies) {
    return fmt::format(
        "{} launched with {} particles and {} bodies on buffers allocated for {} and {}",
        kernel_name(k), p.particle_count, p.body_count, sizes.particles, sizes.bodies);
  }
  if (k == Kernel::ParticlesDisplacement) {
    if (sizes.partition != 0) return {};
    return fmt::format("{} launched on buffers allocated without a partition (Sizes::partition)",
                       kernel_name(k));
  }
  const std::uint64_t words =
      std::uint64_t{p.halo_first} + p.halo_particles + std::uint64_t{p.halo_bodies};
  const std::uint64_t vec4s = std::uint64_t{MOTES_HALO_PARTICLE_VEC4S} * p.halo_particles +
                              std::uint64_t{MOTES_HALO_BODY_VEC4S} * p.halo_bodies;
  if (words <= sizes.halo_index && vec4s <= sizes.halo_data) return {};
  return fmt::format(
      "{} launched with {} particle and {} body entries from HaloIndex word {} ({} words, {} "
      "vec4s of HaloData) on buffers allocated for {} words and {} vec4s",
      kernel_name(k), p.halo_particles, p.halo_bodies, p.halo_first, words, vec4s, sizes.halo_index,
      sizes.halo_data);
}

std::string energy_launch_error(Kernel k, const shared::StepParams& p, const Sizes& sizes) {
  if (k != Kernel::EnergyReduce) return {};
  const std::uint64_t allocated = shared::energy_items(
      sizes.bodies, sizes.particles, std::min(sizes.rigid_particles, sizes.particles));
  if (p.body_count <= sizes.bodies && p.rigid_particle_count <= p.particle_count &&
      p.particle_count <= sizes.particles &&
      shared::energy_blocks(
          shared::energy_items(p.body_count, p.particle_count, p.rigid_particle_count)) <=
          shared::energy_blocks(static_cast<shared::uint>(allocated))) {
    return {};
  }
  return fmt::format(
      "{} launched with {} bodies and particles [{}, {}) on buffers allocated for {} bodies and "
      "{} particles ({} rigid)",
      kernel_name(k), p.body_count, p.rigid_particle_count, p.particle_count, sizes.bodies,
      sizes.particles, sizes.rigid_particles);
}

void* Device::allocate_host(std::size_t bytes) {
  constexpr std::size_t kAlign = 64;
  return ::operator new (std::max<std::size_t>(bytes, 1), std::align_val_t{kAlign}, std::nothrow);
}

void Device::free_host(void* memory) {
  constexpr std::size_t kAlign = 64;
  ::operator delete (memory, std::align_val_t{kAlign});
}

Result<std::vector<unsigned char>> Device::share_halo_outbox(std::size_t /*bytes*/) {
  return std::vector<unsigned char>{};
}

Status Device::publish_halo_outbox(std::size_t /*bytes*/) {
  return Status::error(
      fmt::format("{}: no device-direct halo (publish_halo_outbox)", info().backend));
}

Result<std::size_t> Device::open_peer_outbox(const std::vector<unsigned char>& /*handle*/) {
  return Status::error(fmt::format("{}: no device-direct halo (open_peer_outbox)", info().backend));
}

Status Device::fetch_peer_outbox(std::size_t /*peer*/, std::size_t /*from*/, std::size_t /*to*/,
                                 std::size_t /*bytes*/) {
  return Status::error(
      fmt::format("{}: no device-direct halo (fetch_peer_outbox)", info().backend));
}

BufferSize Device::largest_buffer(const Sizes& sizes) const {
  BufferSize largest;
  for (std::size_t i = 0; i < kBufferCount; ++i) {
    const std::uint64_t bytes = buffer_layout(static_cast<Buffer>(i), sizes).bytes();
    if (bytes > largest.bytes || largest.name.empty()) {
      largest = {buffer_name(static_cast<Buffer>(i)), bytes};
    }
  }
  return largest;
}

DeviceFit device_fit(const Device& device, const Sizes& sizes, std::uint64_t have) {
  DeviceFit f;
  f.need = device.required_bytes(sizes);
  f.have = have;
  f.largest = device.largest_buffer(sizes);
  f.limit = device.buffer_limit();
  return f;
}

std::uint32_t largest_fitting_particles(const Device& device, const Sizes& sizes,
                                        std::uint64_t have) {
  // Needs grow with N (the table in powers of two): bisect on [0, N] for the last that fits.
  const auto fits = [&](std::uint32_t n) {
    return device_fit(device, scale_sizes(sizes, n), have).fits();
  };
  if (fits(sizes.particles)) return sizes.particles;
  std::uint32_t lo = 0;                // fits (or nothing does)
  std::uint32_t hi = sizes.particles;  // does not fit
  while (hi - lo > 1) {
    const std::uint32_t mid = lo + (hi - lo) / 2;
    (fits(mid) ? lo : hi) = mid;
  }
  return lo;
}

namespace {

/// "2.00 GiB (2147483648 bytes)", or in MiB below 1 GiB.
std::string gib(std::uint64_t bytes) {
  const auto b = static_cast<double>(bytes);
  if (bytes < (std::uint64_t{1} << 30)) {
    return fmt::format("{:.2f} MiB ({} bytes)", b / 1048576.0, bytes);
  }
  return fmt::format("{:.2f} GiB ({} bytes)", b / 1073741824.0, bytes);
}

}  // namespace

Status check_device_fits(const Device& device, const Sizes& sizes) {
  const std::uint64_t have = device.available_bytes();
  const DeviceFit f = device_fit(device, sizes, have);
  if (f.fits()) return Status::ok();
  const DeviceInfo& info = device.info();
  std::vector<std::string> reasons;
  if (!f.buffers_fit()) {
    reasons.push_back(fmt::format(
        "buffer {} would need {} bytes, more than the {} bytes one buffer may hold there ({})",
        f.largest.name, f.largest.bytes, f.limit.bytes, f.limit.what));
  }
  if (!f.memory_fits()) {
    reasons.push_back(
        fmt::format("they would need {} of device memory, and the device has {} available",
                    gib(f.need), gib(f.have)));
  }
  const std::uint32_t largest = largest_fitting_particles(device, sizes, have);
  std::string advice =
      largest == 0
          ? std::string("not even one particle fits")
          : fmt::format(
                "at most {} particles fit ({:.1f}% of this scene, in its proportions)", largest,
                std::floor(1000.0 * largest / std::max<double>(sizes.particles, 1.0)) / 10.0);
  if (f.largest.name == "NeighbourList" && !f.buffers_fit() && sizes.neighbour_capacity > 1) {
    advice +=
        fmt::format(", or lower settings.neighbour_capacity (now {})", sizes.neighbour_capacity);
  }
  return Status::error(fmt::format("{} particles do not fit on {} device {} ({}): {}; {}",
                                   sizes.particles, info.backend, info.index, info.name,
                                   fmt::join(reasons, "; and "), advice));
}

Status Device::write_at(Buffer b, std::size_t offset, const void* src, std::size_t bytes) {
  if (bytes == 0) return Status::ok();
  std::vector<unsigned char> head(offset + bytes);
  if (Status s = read(b, head.data(), offset); !s) return s;
  std::memcpy(head.data() + offset, src, bytes);
  return write(b, head.data(), head.size());
}

}  // namespace motes
