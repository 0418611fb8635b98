// constraints_relax on Vulkan: every sweep over every colour in one workgroup
// (shaders/constraints_relax.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_constraints_relax(VkCommandBuffer cb, const shared::StepParams& p) const {
  if (p.constraint_count > 0 && p.constraint_sweeps > 0) {
    dispatch(cb, Pipeline::ConstraintsRelax, p, WORKGROUP_SIZE);
  }
}

}  // namespace motes::vulkan
