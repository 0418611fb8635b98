// particles_check on Vulkan: four dispatches of shaders/particles_check.comp (pass in args.x), a
// barrier between each: the reset, the reduction, the first fastest particle, its speed.
#include "shared/motion_check.h"
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_particles_check(VkCommandBuffer cb, const shared::StepParams& p) const {
  dispatch(cb, Pipeline::ParticlesCheck, p, 1, MOTES_MOTION_PASS_RESET);
  if (p.particle_count == 0) return;
  barrier(cb);
  dispatch(cb, Pipeline::ParticlesCheck, p, p.particle_count, MOTES_MOTION_PASS_REDUCE);
  barrier(cb);
  dispatch(cb, Pipeline::ParticlesCheck, p, p.particle_count, MOTES_MOTION_PASS_FASTEST);
  barrier(cb);
  dispatch(cb, Pipeline::ParticlesCheck, p, 1, MOTES_MOTION_PASS_SPEED);
}

}  // namespace motes::vulkan
