// The viewer's own Vulkan instance and device with a graphics queue (apart from the compute
// backend's): loaded by volk, device functions through a table so that the compute backend's
// device stays the one behind volk's global functions.
#pragma once

#include <volk.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

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
  /// discrete, integrated, virtual, then CPU; makes the device, queue and command pool.
  void open(VkSurfaceKHR surface);

  /// Throws when the validation layer said anything since the last call (every message text).
  void check_messages() const;

  /// One-time command buffer: begin, record, submit, wait.
  VkCommandBuffer begin_commands() const;
  void submit_and_wait(VkCommandBuffer cmd) const;

  /// A memory type index with `flags` among `bits`; throws when none.
  std::uint32_t memory_type(std::uint32_t bits, VkMemoryPropertyFlags flags) const;

  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  std::uint32_t family = 0;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VolkDeviceTable vk{};
  std::string name;  ///< the physical device's name

 private:
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  std::unique_ptr<Messages> messages_;
};

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
