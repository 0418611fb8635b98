// fluid_density on Vulkan: one thread per fluid particle (shaders/fluid_density.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_fluid_density(VkCommandBuffer cb, const shared::StepParams& p) const {
  if (p.fluid_count > 0) dispatch(cb, Pipeline::FluidDensity, p, p.fluid_count);
}

}  // namespace motes::vulkan
