// neighbours_update on Vulkan (shaders/neighbours_update.comp): it copies the
// indirect arguments of every rebuild pass from their template (written at allocate) when
// NeighbourState asks for a rebuild, or zeroes them; the grid_build and neighbours_build passes are
// then dispatched indirectly, so a recorded step replays without the host deciding anything.
// A small grid (at most small_rebuild_table_ buckets: 65,536 on a GPU by default, or
// MOTES_VULKAN_SMALL_REBUILD) is rebuilt by one workgroup instead
// (shaders/neighbours_update_small.glsl), which gates a directly dispatched neighbours_build: two
// dispatches a step where the indirect rebuild has ten, most of them empty.
#include "vulkan_device.h"

namespace motes::vulkan {

void VulkanDevice::record_neighbours_update(VkCommandBuffer cb, const shared::StepParams& p,
                                            std::vector<Kernel>* spans,
                                            std::uint32_t& query) const {
  // Timed: a pair of timestamps around the decision and around each family it may run.
  const auto stamp = [&](bool begin, Kernel k) {
    if (spans == nullptr) return;
    vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, queries_, query++);
    if (begin) spans->push_back(k);
  };
  if (std::uint64_t{p.table_mask} + 1 <= small_rebuild_table_) {
    // A small grid: one workgroup decides and builds the grid, then the gated list build, both
    // dispatched directly (timed: the decision with the grid as grid_build's span).
    const std::uint32_t gate = rebuild_gate_word();
    const std::uint32_t decide[4] = {gate, 0, 0, 0};
    stamp(true, Kernel::NeighboursUpdate);
    stamp(false, Kernel::NeighboursUpdate);
    stamp(true, Kernel::GridBuild);
    dispatch_groups(cb, Pipeline::NeighboursUpdateSmall, p, 1, decide);
    barrier(cb);
    stamp(false, Kernel::GridBuild);
    stamp(true, Kernel::NeighboursBuild);
    std::vector<Pass> build = neighbours_build_passes(p);
    for (Pass& pass : build) {
      pass.args[0] = gate;
      pass.args[1] = 1;  // gated
    }
    record_passes(cb, build, p);
    barrier(cb);
    stamp(false, Kernel::NeighboursBuild);
    return;
  }
  const std::uint32_t words = rebuild_passes_ * 4;
  const std::uint32_t args[4] = {words, words, 0, 0};
  stamp(true, Kernel::NeighboursUpdate);
  dispatch_groups(cb, Pipeline::NeighboursUpdate, p, 1, args);
  barrier(cb, Sync::Indirect);
  stamp(false, Kernel::NeighboursUpdate);
  const std::vector<Pass> grid = grid_build_passes(p);
  stamp(true, Kernel::GridBuild);
  record_passes(cb, grid, p, 0);
  barrier(cb);
  stamp(false, Kernel::GridBuild);
  stamp(true, Kernel::NeighboursBuild);
  record_passes(cb, neighbours_build_passes(p), p, static_cast<int>(grid.size()));
  barrier(cb);
  stamp(false, Kernel::NeighboursBuild);
}

void VulkanDevice::record_neighbours_update(VkCommandBuffer cb, const shared::StepParams& p) const {
  std::uint32_t query = 0;
  record_neighbours_update(cb, p, nullptr, query);
}

}  // namespace motes::vulkan
