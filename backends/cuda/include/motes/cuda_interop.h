// A CUDA simulation's particles copied, device to device, into memory another API made and
// exported (Vulkan's VK_KHR_external_memory_fd): how `motes view` draws a CUDA run without a
// trip through the host (docs/viewer.md, "How it draws"; docs/api.md, "CUDA interop"). Installed
// when motes is built with CUDA; it needs no CUDA header.
//
// Synchronization is by the host: copy_particles returns when the copy is complete, so a draw
// submitted after it sees the particles; the program must wait for its reads of the memory (a
// fence) before the next copy_particles.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>

#include "motes/api.h"
#include "motes/simulation.h"
#include "motes/status.h"

MOTES_API_BEGIN
namespace motes {

/// The UUID of the GPU a simulation on the CUDA backend runs on (cudaDeviceProp::uuid): the same
/// GPU in Vulkan has it as VkPhysicalDeviceIDProperties::deviceUUID. Error: `sim` is not on CUDA.
Result<std::array<std::uint8_t, 16>> cuda_device_uuid(Simulation& sim);

/// Memory of another API imported into CUDA on a simulation's GPU (cudaImportExternalMemory),
/// mapped as one linear buffer.
class CudaImportedMemory {
 public:
  /// Imports `bytes` of memory (the whole allocation) from `fd`, an opaque POSIX file descriptor
  /// (VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT) on `sim`'s GPU; `dedicated`: the allocation
  /// was a dedicated one. On success CUDA owns `fd` (and closes it); on error it stays the
  /// caller's. Errors: `sim` is not on CUDA, or the driver refuses (the reason).
  static Result<std::unique_ptr<CudaImportedMemory>> import_fd(Simulation& sim, int fd,
                                                               std::uint64_t bytes, bool dedicated);
  ~CudaImportedMemory();
  CudaImportedMemory(const CudaImportedMemory&) = delete;
  CudaImportedMemory& operator=(const CudaImportedMemory&) = delete;

  /// Copies `sim`'s particle positions (vec4: centre, radius) to `positions_offset` and, when
  /// given, its velocities (vec4: velocity, inverse mass) to `velocities_offset`, in the device's
  /// particle order (Simulation::scene_particle_order); returns when the copy is complete. `sim`
  /// must be the simulation the memory was imported for. Errors: the copy would pass the end.
  Status copy_particles(Simulation& sim, std::uint64_t positions_offset,
                        std::optional<std::uint64_t> velocities_offset);

 private:
  struct Impl;
  explicit CudaImportedMemory(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace motes
MOTES_API_END
