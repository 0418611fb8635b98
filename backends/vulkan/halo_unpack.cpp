// halo_unpack on Vulkan: one thread per halo entry (shaders/halo_unpack.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_halo_unpack(VkCommandBuffer cb, const shared::StepParams& p) const {
  dispatch(cb, Pipeline::HaloUnpack, p, std::uint64_t{p.halo_particles} + p.halo_bodies);
}

}  // namespace motes::vulkan
