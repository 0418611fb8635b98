// particles_update on Vulkan: particle pose from the body pose (shaders/particles_update.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_particles_update(VkCommandBuffer cb, const shared::StepParams& p) const {
  dispatch(cb, Pipeline::ParticlesUpdate, p, p.rigid_particle_count);
}

}  // namespace motes::vulkan
