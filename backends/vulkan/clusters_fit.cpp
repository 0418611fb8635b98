// clusters_fit on Vulkan: one thread per shape-matching cluster (shaders/clusters_fit.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_clusters_fit(VkCommandBuffer cb, const shared::StepParams& p) const {
  if (p.cluster_count > 0) dispatch(cb, Pipeline::ClustersFit, p, p.cluster_count);
}

}  // namespace motes::vulkan
