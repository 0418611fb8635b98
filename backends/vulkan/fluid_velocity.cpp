// fluid_velocity on Vulkan: one thread per fluid particle, with MOTES_FLAG_FLUID_ADHESION one per
// particle (shaders/fluid_velocity.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_fluid_velocity(VkCommandBuffer cb, const shared::StepParams& p) const {
  const bool solids = (p.flags & MOTES_FLAG_FLUID_ADHESION) != 0u;
  const std::uint32_t n = solids ? p.particle_count : p.fluid_count;
  if (n > 0) dispatch(cb, Pipeline::FluidVelocity, p, n);
}

}  // namespace motes::vulkan
