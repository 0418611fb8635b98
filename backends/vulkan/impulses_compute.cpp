// impulses_compute on Vulkan: one thread per rigid particle (shaders/impulses_compute.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_impulses_compute(VkCommandBuffer cb, const shared::StepParams& p) const {
  dispatch(cb, Pipeline::ImpulsesCompute, p, p.rigid_particle_count);
}

}  // namespace motes::vulkan
