// The Vulkan objects a device needs: instance (loaded at run time by volk), validation messages,
// the chosen physical device, a logical device with one compute queue, a command pool and a fence.
#pragma once

#include <volk.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "motes/backend/device.h"
#include "motes/status.h"

namespace motes::vulkan {

/// "VK_ERROR_OUT_OF_DEVICE_MEMORY" and friends.
const char* result_name(VkResult r);

/// Messages of the validation layer, collected by its callback.
struct MessageLog {
  std::mutex mutex;
  std::vector<std::string> messages;
};

/// One physical device as motes sees it.
struct PhysicalDevice {
  VkPhysicalDevice handle = VK_NULL_HANDLE;
  DeviceInfo info;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  std::uint32_t compute_family = UINT32_MAX;  ///< a queue family with compute; UINT32_MAX: none
  std::uint32_t timestamp_bits = 0;           ///< of that family; 0 = no timestamps
  float timestamp_period_ns = 0.0f;
  std::uint32_t subgroup_size = 0;
  bool subgroup_arithmetic = false;     ///< subgroupAdd and friends in compute shaders
  std::uint32_t max_workgroup_x = 0;    ///< invocations of a 1D workgroup: the lower of the limits
  std::uint64_t max_storage_range = 0;  ///< maxStorageBufferRange
  std::uint64_t max_allocation = 0;     ///< maxMemoryAllocationSize
};

/// The instance and what it sees. Destroys the instance (and messenger) last.
class Instance {
 public:
  /// Loads Vulkan, creates an instance (with validation when asked), lists physical devices.
  static Result<std::unique_ptr<Instance>> create(bool validation);
  /// A program's instance (motes/vulkan_interop.h), described like one motes made; never
  /// destroyed here. Loads Vulkan when motes has not yet.
  static Result<std::unique_ptr<Instance>> adopt(VkInstance instance);
  ~Instance();
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;

  [[nodiscard]] VkInstance handle() const { return instance_; }
  [[nodiscard]] const std::vector<PhysicalDevice>& devices() const { return devices_; }
  /// Index of the preferred device (discrete, integrated, virtual, CPU), -1 when none computes.
  [[nodiscard]] int preferred() const;
  [[nodiscard]] bool validation() const { return messenger_ != VK_NULL_HANDLE; }
  [[nodiscard]] MessageLog& log() { return *log_; }

 private:
  Instance() = default;
  /// Lists the physical devices of instance_.
  void describe_devices();
  VkInstance instance_ = VK_NULL_HANDLE;
  bool owned_ = true;  ///< false for a program's instance (adopt)
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  std::unique_ptr<MessageLog> log_ = std::make_unique<MessageLog>();
  std::vector<PhysicalDevice> devices_;
};

/// True when MOTES_VULKAN_VALIDATION is set to something other than 0.
bool validation_requested();

/// The process's one instance, made on first use (with validation when validation_requested())
/// and destroyed at exit, once the last device is gone (destroy devices before exit: a device
/// that outlives the exit handlers outlives the driver). An instance per device is wasteful, and
/// NVIDIA's driver refused new instances (VK_ERROR_INCOMPATIBLE_DRIVER) after about fifty had come
/// and gone.
Result<std::shared_ptr<Instance>> shared_instance();

}  // namespace motes::vulkan
