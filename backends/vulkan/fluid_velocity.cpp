// fluid_velocity on Vulkan: one thread per fluid particle (shaders/fluid_velocity.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_fluid_velocity(VkCommandBuffer cb, const shared::StepParams& p) const {
  if (p.fluid_count > 0) dispatch(cb, Pipeline::FluidVelocity, p, p.fluid_count);
}

}  // namespace motes::vulkan
