// motes on a program's Vulkan device and its particle buffers (motes/vulkan_interop.h).
#include "motes/vulkan_interop.h"

#include <fmt/format.h>

#include <vector>

#include "queue_family.h"
#include "vulkan_device.h"

namespace motes {

Result<std::unique_ptr<Device>> open_vulkan_device(const VulkanHandles& handles) {
  const char* null_handle = handles.instance == VK_NULL_HANDLE          ? "instance"
                            : handles.physical_device == VK_NULL_HANDLE ? "physical_device"
                            : handles.device == VK_NULL_HANDLE          ? "device"
                                                                        : nullptr;
  if (null_handle != nullptr) {
    return Status::error(
        fmt::format("open_vulkan_device: VulkanHandles::{} is VK_NULL_HANDLE", null_handle));
  }
  Result<std::unique_ptr<vulkan::Instance>> adopted = vulkan::Instance::adopt(handles.instance);
  if (!adopted) return Status::error("open_vulkan_device: " + adopted.message());
  std::shared_ptr<vulkan::Instance> instance = std::move(adopted.value());
  int physical = -1;
  for (std::size_t i = 0; i < instance->devices().size(); ++i) {
    if (instance->devices()[i].handle == handles.physical_device) physical = static_cast<int>(i);
  }
  if (physical < 0) {
    return Status::error(
        "open_vulkan_device: the physical device is not one of the instance's (from another "
        "instance?)");
  }
  VkPhysicalDeviceProperties props{};
  vkGetPhysicalDeviceProperties(handles.physical_device, &props);
  if (props.apiVersion < VK_API_VERSION_1_2) {
    return Status::error(fmt::format(
        "open_vulkan_device: {} supports Vulkan {}.{}; motes needs 1.2", props.deviceName,
        VK_API_VERSION_MAJOR(props.apiVersion), VK_API_VERSION_MINOR(props.apiVersion)));
  }
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(handles.physical_device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(handles.physical_device, &count, families.data());
  if (std::string why =
          vulkan::queue_family_error(families, handles.queue_family, handles.queue_index);
      !why.empty()) {
    return Status::error(fmt::format("open_vulkan_device ({}): {}", props.deviceName, why));
  }
  Result<std::unique_ptr<vulkan::VulkanDevice>> d =
      vulkan::VulkanDevice::adopt(std::move(instance), physical, handles.device,
                                  handles.queue_family, handles.queue_index, handles.memory_budget);
  if (!d) return d.status();
  std::unique_ptr<Device> out = std::move(d.value());
  return out;
}

Result<VulkanParticleBuffers> vulkan_particle_buffers(Simulation& sim) {
  Device& base = sim.device();
  const DeviceInfo& info = base.info();
  auto* device = dynamic_cast<vulkan::VulkanDevice*>(&base);
  if (device == nullptr) {
    return Status::error(fmt::format(
        "vulkan_particle_buffers: the simulation runs on {} ({}), not on a Vulkan device",
        info.backend, info.name));
  }
  if (!device->on_program_device()) {
    return Status::error(fmt::format(
        "vulkan_particle_buffers: the simulation runs on motes' own Vulkan device ({}), whose "
        "buffers no other device can use; open it on yours with open_vulkan_device",
        info.name));
  }
  auto range = [&](Buffer b) {
    VulkanBufferRange r;
    r.buffer = device->buffer_handle(b);
    r.stride = sizeof(shared::vec4);
    r.count = sim.particle_count();
    r.size = r.stride * r.count;
    return r;
  };
  return VulkanParticleBuffers{range(Buffer::ParticlePos), range(Buffer::ParticleVel)};
}

}  // namespace motes
