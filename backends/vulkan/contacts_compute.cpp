// contacts_compute on Vulkan: every particle gathers its contacts over the 27 neighbouring cells in
// the canonical order, then the planes: forces (shaders/contacts_compute.comp), or with
// MOTES_FLAG_POSITION the shifts of position contacts (shaders/contacts_compute_shift.comp), a
// shader of its own so that the force law's carries none of the shifts' code.
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_contacts_compute(VkCommandBuffer cb, const shared::StepParams& p) const {
  const bool shifts = (p.flags & MOTES_FLAG_POSITION) != 0u;
  dispatch(cb, shifts ? Pipeline::ContactsComputeShift : Pipeline::ContactsCompute, p,
           p.particle_count);
}

}  // namespace motes::vulkan
