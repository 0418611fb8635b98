// Memory shared by the viewer and a CUDA simulation (cuda_share.h).
#include "cuda_share.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <optional>
#include <stdexcept>

#ifdef MOTES_VIEWER_CUDA
#include "motes/cuda_interop.h"
#endif

namespace motes::viewer {

struct CudaShare::Imported {
#ifdef MOTES_VIEWER_CUDA
  std::unique_ptr<CudaImportedMemory> memory;
#endif
};

std::string CudaShare::why_not(const Gpu& gpu, Simulation& sim) {
#ifdef MOTES_VIEWER_CUDA
  Result<std::array<std::uint8_t, 16>> uuid = cuda_device_uuid(sim);
  if (!uuid) return uuid.message();
  if (std::memcmp(uuid->data(), gpu.uuid.data(), gpu.uuid.size()) != 0) {
    return fmt::format("the viewer's Vulkan device {} is not the simulation's GPU {}", gpu.name,
                       sim.device().info().name);
  }
  if (!gpu.external_memory_fd) {
    return fmt::format("{} lacks VK_KHR_external_memory_fd", gpu.name);
  }
  return {};
#else
  (void)gpu;
  return fmt::format("the {} backend, and this build has no CUDA", sim.device().info().backend);
#endif
}

CudaShare::CudaShare(const Gpu& gpu, Simulation& sim, bool velocities)
    : gpu_(gpu), velocities_(velocities), imported_(std::make_unique<Imported>()) {
#ifdef MOTES_VIEWER_CUDA
  constexpr VkDeviceSize kVec4 = 16;
  const VkDeviceSize particles = std::max<VkDeviceSize>(sim.particle_count(), 1);
  velocities_offset_ = kVec4 * particles;
  const VkDeviceSize wanted = velocities ? 2 * velocities_offset_ : velocities_offset_;
  VkExternalMemoryBufferCreateInfo external{};
  external.sType = VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO;
  external.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.pNext = &external;
  info.size = wanted;
  info.usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(gpu_.vk.vkCreateBuffer(gpu_.device, &info, nullptr, &buffer_), "vkCreateBuffer (shared)");
  VkMemoryRequirements req{};
  gpu_.vk.vkGetBufferMemoryRequirements(gpu_.device, buffer_, &req);
  // A dedicated allocation, as CUDA's import is told (cudaExternalMemoryDedicated).
  VkMemoryDedicatedAllocateInfo dedicated{};
  dedicated.sType = VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO;
  dedicated.buffer = buffer_;
  VkExportMemoryAllocateInfo exported{};
  exported.sType = VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO;
  exported.pNext = &dedicated;
  exported.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  memory_ = gpu_.allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &exported);
  check(gpu_.vk.vkBindBufferMemory(gpu_.device, buffer_, memory_, 0), "vkBindBufferMemory");
  size_ = req.size;
  VkMemoryGetFdInfoKHR get{};
  get.sType = VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR;
  get.memory = memory_;
  get.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  int fd = -1;
  check(gpu_.vk.vkGetMemoryFdKHR(gpu_.device, &get, &fd), "vkGetMemoryFdKHR");
  Result<std::unique_ptr<CudaImportedMemory>> memory =
      CudaImportedMemory::import_fd(sim, fd, req.size, true);
  if (!memory) {
    close(fd);  // still ours
    throw std::runtime_error("viewer: " + memory.message());
  }
  imported_->memory = std::move(memory.value());
#else
  (void)velocities;
  throw std::runtime_error("viewer: " + why_not(gpu, sim));
#endif
}

CudaShare::~CudaShare() {
  imported_.reset();  // CUDA's mapping and import go first
  if (buffer_ != VK_NULL_HANDLE) gpu_.vk.vkDestroyBuffer(gpu_.device, buffer_, nullptr);
  if (memory_ != VK_NULL_HANDLE) gpu_.vk.vkFreeMemory(gpu_.device, memory_, nullptr);
}

void CudaShare::copy(Simulation& sim) {
#ifdef MOTES_VIEWER_CUDA
  const Status s = imported_->memory->copy_particles(
      sim, 0, velocities_ ? std::optional<std::uint64_t>(velocities_offset_) : std::nullopt);
  if (!s) throw std::runtime_error("viewer: " + s.message());
#else
  (void)sim;
#endif
}

namespace {

/// The whole of `buffer` passed between queue families `from` and `to` (one of them
/// VK_QUEUE_FAMILY_EXTERNAL: CUDA's side); `reads`: the accesses of the viewer's side.
VkBufferMemoryBarrier ownership(VkBuffer buffer, std::uint32_t from, std::uint32_t to,
                                VkAccessFlags reads) {
  VkBufferMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
  b.srcAccessMask = 0;  // CUDA's writes are finished and visible (the host waited for them)
  b.dstAccessMask = reads;
  b.srcQueueFamilyIndex = from;
  b.dstQueueFamilyIndex = to;
  b.buffer = buffer;
  b.offset = 0;
  b.size = VK_WHOLE_SIZE;
  return b;
}

constexpr VkPipelineStageFlags kReadStages = VK_PIPELINE_STAGE_VERTEX_INPUT_BIT |
                                             VK_PIPELINE_STAGE_VERTEX_SHADER_BIT |
                                             VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;

}  // namespace

void CudaShare::record_acquire(VkCommandBuffer cmd) const {
  const VkBufferMemoryBarrier b =
      ownership(buffer_, VK_QUEUE_FAMILY_EXTERNAL, gpu_.family,
                VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
  gpu_.vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, kReadStages, 0, 0, nullptr,
                               1, &b, 0, nullptr);
}

void CudaShare::record_release(VkCommandBuffer cmd) const {
  // Reads only: nothing to make available.
  const VkBufferMemoryBarrier b = ownership(buffer_, gpu_.family, VK_QUEUE_FAMILY_EXTERNAL, 0);
  gpu_.vk.vkCmdPipelineBarrier(cmd, kReadStages, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0,
                               nullptr, 1, &b, 0, nullptr);
}

}  // namespace motes::viewer
