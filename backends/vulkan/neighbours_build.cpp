// neighbours_build on Vulkan (shaders/neighbours_build_begin.comp, neighbours_build.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

std::vector<VulkanDevice::Pass> VulkanDevice::neighbours_build_passes(
    const shared::StepParams& p) const {
  return {{Pipeline::NeighboursBuild,
           (std::uint64_t{p.particle_count} + WORKGROUP_SIZE - 1) / WORKGROUP_SIZE,
           {}}};
}

void VulkanDevice::record_neighbours_build(VkCommandBuffer cb, const shared::StepParams& p) const {
  // On its own the build starts with neighbours_build_begin; in neighbours_update,
  // neighbours_update.comp starts it.
  std::vector<Pass> passes = {{Pipeline::NeighboursBuildBegin, 1, {}}};
  for (const Pass& pass : neighbours_build_passes(p)) passes.push_back(pass);
  record_passes(cb, passes, p);
}

}  // namespace motes::vulkan
