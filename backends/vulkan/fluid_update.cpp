// fluid_update on Vulkan: one thread per particle (shaders/fluid_update.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_fluid_update(VkCommandBuffer cb, const shared::StepParams& p) const {
  if (p.particle_count > 0) dispatch(cb, Pipeline::FluidUpdate, p, p.particle_count);
}

}  // namespace motes::vulkan
