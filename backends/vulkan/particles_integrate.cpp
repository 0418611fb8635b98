// particles_integrate on Vulkan: one thread per free sphere (shaders/particles_integrate.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_particles_integrate(VkCommandBuffer cb,
                                              const shared::StepParams& p) const {
  if (p.particle_count > p.rigid_particle_count) {
    dispatch(cb, Pipeline::ParticlesIntegrate, p, p.particle_count - p.rigid_particle_count);
  }
}

}  // namespace motes::vulkan
