// clusters_fit on Vulkan: 32 threads per shape-matching cluster (shaders/clusters_fit.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_clusters_fit(VkCommandBuffer cb, const shared::StepParams& p) const {
  constexpr std::uint64_t kLanes = 32;  // threads per cluster: LANES in the shader
  if (p.cluster_count > 0) dispatch(cb, Pipeline::ClustersFit, p, p.cluster_count * kLanes);
}

}  // namespace motes::vulkan
