// bodies_integrate on Vulkan: one semi-implicit Euler step per body
// (shaders/bodies_integrate.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_bodies_integrate(VkCommandBuffer cb, const shared::StepParams& p) const {
  dispatch(cb, Pipeline::BodiesIntegrate, p, p.body_count);
}

}  // namespace motes::vulkan
