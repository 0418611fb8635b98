// impulses_apply on Vulkan: one thread per rigid body (shaders/impulses_apply.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_impulses_apply(VkCommandBuffer cb, const shared::StepParams& p) const {
  dispatch(cb, Pipeline::ImpulsesApply, p, p.body_count);
}

}  // namespace motes::vulkan
