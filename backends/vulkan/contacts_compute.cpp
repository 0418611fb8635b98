// contacts_compute on Vulkan: every particle gathers its contacts over the 27 neighbouring cells in
// the canonical order, then the planes (shaders/contacts_compute.comp).
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_contacts_compute(VkCommandBuffer cb, const shared::StepParams& p) const {
  dispatch(cb, Pipeline::ContactsCompute, p, p.particle_count);
}

}  // namespace motes::vulkan
