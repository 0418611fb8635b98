// halo_pack on Vulkan: one thread per halo entry (shaders/halo_pack.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_halo_pack(VkCommandBuffer cb, const shared::StepParams& p) const {
  dispatch(cb, Pipeline::HaloPack, p, std::uint64_t{p.halo_particles} + p.halo_bodies);
}

}  // namespace motes::vulkan
