// impulses_apply on Vulkan: one thread per rigid body (shaders/impulses_apply.comp), and a
// workgroup per body of kWideBodyParticles or more particles (shaders/impulses_apply_wide.comp:
// the same sums in the same order), each shader skipping the other's bodies (args.x: the size
// from which a body is the wide shader's; 0: none is). With BodyFirst not known, a thread each.
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_impulses_apply(VkCommandBuffer cb, const shared::StepParams& p) const {
  const bool wide = largest_body_ >= kWideBodyParticles;
  const std::uint32_t wide_from = wide ? kWideBodyParticles : 0u;
  if (!wide || smallest_body_ < kWideBodyParticles) {
    dispatch(cb, Pipeline::ImpulsesApply, p, p.body_count, wide_from);
  }
  if (wide) {
    const std::uint32_t args[4] = {wide_from, 0, 0, 0};
    dispatch_groups(cb, Pipeline::ImpulsesApplyWide, p, p.body_count, args);
  }
}

}  // namespace motes::vulkan
