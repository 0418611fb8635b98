// energy_reduce on Vulkan: one dispatch of shaders/energy_reduce.comp, a workgroup per block of
// 256 items (shared/energy.h); nothing to dispatch without items.
#include "shared/energy.h"
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_energy_reduce(VkCommandBuffer cb, const shared::StepParams& p) const {
  const std::uint32_t items =
      shared::energy_items(p.body_count, p.particle_count, p.rigid_particle_count);
  if (items == 0) return;
  dispatch(cb, Pipeline::EnergyReduce, p,
           std::uint64_t{shared::energy_blocks(items)} * MOTES_ENERGY_BLOCK);
}

}  // namespace motes::vulkan
