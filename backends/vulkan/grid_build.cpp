// grid_build on Vulkan: a deterministic counting sort in five passes (shaders/grid_build_*.comp).
// Counting with integer atomics gives each bucket's size and an arbitrary arrival rank; a
// multi-level scan turns the counts into GridCellStart; particles are scattered by arrival rank;
// grid_build_place then puts each particle at its canonical slot (rank by id within the bucket),
// so the result equals the stable sort by (bucket, particle id) of the OpenMP backend exactly.
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_grid_build(VkCommandBuffer cb, const shared::StepParams& p) const {
  const std::uint64_t n = p.particle_count;
  vkCmdFillBuffer(cb, buffer(B_GRID_CELL_START), 0, (std::uint64_t{sizes_.table} + 1) * 4, 0);
  barrier(cb);
  dispatch(cb, Pipeline::GridBuildCount, p, n);
  barrier(cb);
  for (const ScanLevel& l : scan_levels_) {
    const std::uint32_t args[4] = {l.in_scratch, l.offset, l.count, l.sums_offset};
    dispatch_groups(cb, Pipeline::GridBuildScanBlock, p, (l.count + SCAN_BLOCK - 1) / SCAN_BLOCK,
                    args);
    barrier(cb);
  }
  // Top down: each level below the last adds its block offsets, scanned one level up.
  for (std::size_t k = scan_levels_.size() - 1; k-- > 0;) {
    const ScanLevel& l = scan_levels_[k];
    dispatch(cb, Pipeline::GridBuildScanAdd, p, l.count, l.in_scratch, l.offset, l.count,
             l.sums_offset);
    barrier(cb);
  }
  dispatch(cb, Pipeline::GridBuildScatter, p, n);
  barrier(cb);
  dispatch(cb, Pipeline::GridBuildPlace, p, n);
}

}  // namespace motes::vulkan
