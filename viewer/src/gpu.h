// The viewer's own Vulkan instance and device with a graphics queue (apart from the compute
// backend's): loaded by volk, device functions through a table so that the compute backend's
// device stays the one behind volk's global functions.
#pragma once

#include <volk.h>

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "motes/vulkan_interop.h"

namespace motes::viewer {

/// "VK_ERROR_DEVICE_LOST" and friends.
const char* result_name(VkResult r);
/// Throws std::runtime_error "what: VK_ERROR_..." unless `r` is VK_SUCCESS.
void check(VkResult r, const char* what);

struct Messages;

class Gpu {
 public:
  /// Loads Vulkan and makes an instance with `extensions` (the window system's); with the
  /// Khronos validation layer when MOTES_VULKAN_VALIDATION is set (not 0).
  explicit Gpu(const std::vector<const char*>& extensions);
  ~Gpu();
  Gpu(const Gpu&) = delete;
  Gpu& operator=(const Gpu&) = delete;

  /// Picks a device with a graphics queue (that presents to `surface`, unless it is null):
  /// physical device `wanted` (in the loader's order) when it has one, else discrete,
  /// integrated, virtual, then CPU; a family that also computes when there is one (so that
  /// motes can run on the same queue); makes the device, queue and command pool.
  void open(VkSurfaceKHR surface, int wanted = -1);

  /// The instance, device and queue for motes::open_vulkan_device (motes/vulkan_interop.h).
  [[nodiscard]] motes::VulkanHandles handles() const;

  /// Throws when the validation layer said anything since the last call (every message text).
  void check_messages() const;

  /// One-time command buffer: begin, record, submit, wait.
  VkCommandBuffer begin_commands() const;
  void submit_and_wait(VkCommandBuffer cmd) const;

  /// A memory type index with `flags` among `bits`; throws when none.
  std::uint32_t memory_type(std::uint32_t bits, VkMemoryPropertyFlags flags) const;
  /// Memory for `req` of a type with `flags` (a buffer's or image's, then bound to it), with
  /// `next` as VkMemoryAllocateInfo's pNext chain (export, dedicated); throws when there is none.
  VkDeviceMemory allocate(const VkMemoryRequirements& req, VkMemoryPropertyFlags flags,
                          const void* next = nullptr) const;

  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  std::uint32_t family = 0;
  bool family_computes = false;     ///< the queue's family has compute too
  int index = -1;                   ///< the physical device's place in the loader's order
  bool memory_budget = false;       ///< VK_EXT_memory_budget is enabled (for motes' device)
  bool external_memory_fd = false;  ///< VK_KHR_external_memory_fd is enabled (cuda_share.h)
  std::array<std::uint8_t, VK_UUID_SIZE> uuid{};  ///< VkPhysicalDeviceIDProperties::deviceUUID
  VkCommandPool pool = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VolkDeviceTable vk{};
  std::string name;  ///< the physical device's name

 private:
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  std::unique_ptr<Messages> messages_;
};

/// motes' compute device on `gpu`'s device and queue (motes::open_vulkan_device), or why not.
Result<std::unique_ptr<Device>> open_compute_device(const Gpu& gpu);

/// A buffer in host-visible, coherent memory, mapped for its lifetime.
struct HostBuffer {
  HostBuffer(const Gpu& gpu, VkDeviceSize size, VkBufferUsageFlags usage);
  ~HostBuffer();
  HostBuffer(const HostBuffer&) = delete;
  HostBuffer& operator=(const HostBuffer&) = delete;

  const Gpu& gpu;
  VkDeviceSize size = 0;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
};

/// A buffer in device-local memory, filled once from the host through a staging copy that is
/// made visible to vertex input.
struct DeviceBuffer {
  DeviceBuffer(const Gpu& gpu, const void* data, VkDeviceSize size, VkBufferUsageFlags usage);
  ~DeviceBuffer();
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;

  const Gpu& gpu;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
};

/// A 2D image in device memory with its view (a colour or depth attachment).
struct DeviceImage {
  DeviceImage(const Gpu& gpu, VkFormat format, VkExtent2D extent, VkImageUsageFlags usage,
              VkImageAspectFlags aspect);
  ~DeviceImage();
  DeviceImage(const DeviceImage&) = delete;
  DeviceImage& operator=(const DeviceImage&) = delete;

  const Gpu& gpu;
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
};

}  // namespace motes::viewer
