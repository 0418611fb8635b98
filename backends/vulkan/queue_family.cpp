// The queue a program gives motes: it exists and computes (queue_family.h).
#include "queue_family.h"

#include <fmt/format.h>

namespace motes::vulkan {

std::string queue_family_error(std::span<const VkQueueFamilyProperties> families,
                               std::uint32_t family, std::uint32_t index) {
  if (family >= families.size()) {
    return fmt::format("queue family {} does not exist (the device has {})", family,
                       families.size());
  }
  const VkQueueFamilyProperties& f = families[family];
  if ((f.queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) {
    return fmt::format(
        "queue family {} has no compute (VK_QUEUE_COMPUTE_BIT), which motes' kernels need", family);
  }
  if (index >= f.queueCount) {
    return fmt::format("queue {} of family {} does not exist (the family has {})", index, family,
                       f.queueCount);
  }
  return {};
}

}  // namespace motes::vulkan
