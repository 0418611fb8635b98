// motes on a program's own Vulkan device, and its particles drawn from motes' buffers without a
// copy (docs/api.md, "Vulkan interop"; examples/embed_vulkan). Installed when motes is built with
// Vulkan; it needs only the Vulkan headers (<vulkan/vulkan_core.h>), not a loader.
//
// The program keeps its instance, physical device, device and queue: motes makes its own command
// pool, fence, descriptor pool, pipelines and buffers on them and frees them when the device is
// destroyed, never the program's objects. Handles must come from the system's Vulkan loader
// (libvulkan.so.1), which motes opens too.
//
// Queue: motes submits to the queue it is given only inside its own calls (Simulation::create,
// step, snapshot, write_state, ...; each waits for its work before it returns, so nothing of
// motes is in flight between calls). The queue is externally synchronized (Vulkan's rule): the
// program must not use it from another thread during a motes call.
//
// Reading motes' buffers (drawing): motes writes ParticlePos and ParticleVel in compute shaders
// and transfers. Before a command that reads them, record on the same queue a memory barrier
// from kVulkanWriteStages / kVulkanWriteAccess to the reading stage and access, e.g.
//     VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr, motes::kVulkanWriteAccess,
//                       VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT};
//     vkCmdPipelineBarrier(cmd, motes::kVulkanWriteStages, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT,
//                          0, 1, &b, 0, nullptr, 0, nullptr);
// The other way round, motes' own command buffers begin with a barrier whose first scope is all
// commands submitted before them on that queue, so a step may follow a draw that reads the
// buffers without waiting for it, as long as both go to that queue. A program that reads the
// buffers on another queue must wait for those reads (a fence) before calling motes again.
// Simulation::create, take_device and destroying the device free and remake the buffers: wait for
// every command that uses them first, and fetch the buffers again after a create.
#pragma once

#include <vulkan/vulkan_core.h>

#include <cstdint>
#include <memory>

#include "motes/api.h"
#include "motes/backend/device.h"
#include "motes/simulation.h"
#include "motes/status.h"

MOTES_API_BEGIN
namespace motes {

/// A program's Vulkan objects to run motes on. What they must have: an instance and a device of
/// Vulkan 1.2 or later (apiVersion), no device features, no extensions; VK_EXT_memory_budget is
/// used when the program enabled it on the device (say so in `memory_budget`): motes then checks
/// a scene against the memory the device has left rather than the heap's size. The queue's family
/// must support compute (and graphics, if the program draws with it).
struct VulkanHandles {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;  ///< one of `instance`'s
  VkDevice device = VK_NULL_HANDLE;                   ///< made from `physical_device`
  std::uint32_t queue_family = 0;
  std::uint32_t queue_index = 0;  ///< a queue the device was created with in that family
  bool memory_budget = false;     ///< VK_EXT_memory_budget is enabled on `device`
};

/// A motes device on the program's Vulkan device, for Simulation::create. Errors (with the reason):
/// a null handle, a physical device that is not the instance's, a device older than Vulkan 1.2,
/// a queue family that does not exist or has no compute, a queue index beyond the family's.
Result<std::unique_ptr<Device>> open_vulkan_device(const VulkanHandles& handles);

/// One of motes' buffers as a program binds it: `count` elements of `stride` bytes from `offset`
/// (the first `size` bytes of the range are the elements; the buffer may be longer).
struct VulkanBufferRange {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceSize offset = 0;
  VkDeviceSize size = 0;
  VkDeviceSize stride = 0;
  std::uint32_t count = 0;
};

/// The particle buffers of a simulation on a device from open_vulkan_device, in the device's
/// particle order (Simulation::scene_particle_order maps it to the scene's). Both are vec4 arrays
/// (16 bytes an element) with VK_BUFFER_USAGE_VERTEX_BUFFER_BIT and STORAGE_BUFFER_BIT: bind
/// them as per-instance vertex buffers (VK_FORMAT_R32G32B32A32_SFLOAT) or storage buffers. Read
/// them only: motes keeps its state there.
struct VulkanParticleBuffers {
  VulkanBufferRange positions;   ///< Buffer::ParticlePos: centre xyz, w = radius
  VulkanBufferRange velocities;  ///< Buffer::ParticleVel: velocity xyz, w = inverse mass
};

/// The particle buffers of `sim` (valid until `sim` is destroyed or its device is taken).
/// Errors: `sim` runs on another backend, or on a Vulkan device motes made itself (its buffers
/// belong to motes' own VkDevice: use open_vulkan_device).
Result<VulkanParticleBuffers> vulkan_particle_buffers(Simulation& sim);

/// The stages and accesses in which motes writes its buffers: the first scope of the barrier a
/// program records before reading them (see the top of this header).
inline constexpr VkPipelineStageFlags kVulkanWriteStages =
    VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
inline constexpr VkAccessFlags kVulkanWriteAccess =
    VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;

}  // namespace motes
MOTES_API_END
