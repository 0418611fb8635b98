// bodies_reduce on Vulkan: force and torque of each body, one thread per body
// (shaders/bodies_reduce.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_bodies_reduce(VkCommandBuffer cb, const shared::StepParams& p) const {
  dispatch(cb, Pipeline::BodiesReduce, p, p.body_count);
}

}  // namespace motes::vulkan
