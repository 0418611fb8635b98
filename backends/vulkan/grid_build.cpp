// grid_build on Vulkan: a deterministic counting sort in six passes (shaders/grid_build_*.comp).
// The bucket counts are zeroed; counting with integer atomics gives each bucket's size and an
// arbitrary arrival rank; a multi-level scan turns the counts into GridCellStart; particles are
// scattered by arrival rank; grid_build.comp (the last pass) then puts each particle at its
// canonical slot (rank by id within the bucket), so the result equals the stable sort by (bucket,
// particle id) of the OpenMP backend exactly.
#include "vulkan_device.h"

namespace motes::vulkan {

namespace {

std::uint64_t groups_for(std::uint64_t threads) {
  return (threads + WORKGROUP_SIZE - 1) / WORKGROUP_SIZE;
}

}  // namespace

std::vector<VulkanDevice::Pass> VulkanDevice::grid_build_passes(const shared::StepParams& p) const {
  const std::uint64_t n = p.particle_count;
  std::vector<Pass> passes;
  passes.push_back({Pipeline::GridBuildClear, groups_for(std::uint64_t{p.table_mask} + 2), {}});
  passes.push_back({Pipeline::GridBuildCount, groups_for(n), {}});
  for (const ScanLevel& l : scan_levels_) {
    passes.push_back({Pipeline::GridBuildScanBlock,
                      (l.count + SCAN_BLOCK - 1) / SCAN_BLOCK,
                      {l.in_scratch, l.offset, l.count, l.sums_offset}});
  }
  // Top down: each level below the last adds its block offsets, scanned one level up.
  for (std::size_t k = scan_levels_.size() - 1; k-- > 0;) {
    const ScanLevel& l = scan_levels_[k];
    passes.push_back({Pipeline::GridBuildScanAdd,
                      groups_for(l.count),
                      {l.in_scratch, l.offset, l.count, l.sums_offset}});
  }
  passes.push_back({Pipeline::GridBuildScatter, groups_for(n), {}});
  passes.push_back({Pipeline::GridBuild, groups_for(n), {}});
  return passes;
}

void VulkanDevice::record_grid_build(VkCommandBuffer cb, const shared::StepParams& p) const {
  record_passes(cb, grid_build_passes(p), p);
}

}  // namespace motes::vulkan
