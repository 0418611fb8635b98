// fluid_vorticity on Vulkan: one thread per fluid particle (shaders/fluid_vorticity.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_fluid_vorticity(VkCommandBuffer cb, const shared::StepParams& p) const {
  if (p.fluid_count > 0) dispatch(cb, Pipeline::FluidVorticity, p, p.fluid_count);
}

}  // namespace motes::vulkan
