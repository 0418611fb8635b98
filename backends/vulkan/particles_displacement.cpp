// particles_displacement on Vulkan: two dispatches of shaders/particles_displacement.comp (pass in
// args.x), a barrier between them: the reset, then the reduction.
#include "shared/halo.h"
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_particles_displacement(VkCommandBuffer cb,
                                                 const shared::StepParams& p) const {
  dispatch(cb, Pipeline::ParticlesDisplacement, p, 1, MOTES_PARTITION_PASS_RESET);
  if (p.particle_count == 0) return;
  barrier(cb);
  dispatch(cb, Pipeline::ParticlesDisplacement, p, p.particle_count, MOTES_PARTITION_PASS_REDUCE);
}

}  // namespace motes::vulkan
