// constraints_solve on Vulkan: one thread per constraint of the colour
// (shaders/constraints_solve.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_constraints_solve(VkCommandBuffer cb, const shared::StepParams& p) const {
  if (p.constraint_count > 0) dispatch(cb, Pipeline::ConstraintsSolve, p, p.constraint_count);
}

}  // namespace motes::vulkan
