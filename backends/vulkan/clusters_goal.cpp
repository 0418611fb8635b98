// clusters_goal on Vulkan: one thread per soft-body particle (shaders/clusters_goal.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_clusters_goal(VkCommandBuffer cb, const shared::StepParams& p) const {
  if (p.cluster_count > 0 && p.linked_first > p.soft_first) {
    dispatch(cb, Pipeline::ClustersGoal, p, p.linked_first - p.soft_first);
  }
}

}  // namespace motes::vulkan
