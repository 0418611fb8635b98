// neighbours_update on Vulkan (shaders/neighbours_update.comp): it sets the rebuild's gate word
// (B_INDIRECT_ARGS, after the template) when NeighbourState asks for a rebuild, and starts the
// build. Where the device has VK_EXT_conditional_rendering, the grid_build and neighbours_build
// passes are recorded between a begin and an end of conditional rendering on that word, so a step
// without a rebuild skips them; otherwise the decision also copies the indirect arguments of every
// pass from their template (written at allocate), or zeroes them, and the passes are dispatched
// indirectly. Either way a recorded step replays without the host deciding anything.
// A small grid (at most small_rebuild_table_ buckets: 65,536 on a GPU by default, or
// MOTES_VULKAN_SMALL_REBUILD) is rebuilt by one workgroup instead
// (shaders/neighbours_update_small.glsl), which sets the same gate word for a neighbours_build
// that reads it: two dispatches a step where the indirect rebuild has ten, most of them empty (not
// skipped by conditional rendering: on an H200 its begin cost more than the gated dispatch,
// docs/benchmarks.md).
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
  // The decision: the gate word (args.z), and with indirect passes their arguments (args.x words
  // from args.y).
  const std::uint32_t words = rebuild_passes_ * 4;
  const std::uint32_t args[4] = {conditional_ ? 0u : words, words, rebuild_gate_word(), 0};
  stamp(true, Kernel::NeighboursUpdate);
  dispatch_groups(cb, Pipeline::NeighboursUpdate, p, 1, args);
  barrier(cb, conditional_ ? Sync::Predicate : Sync::Indirect);
  stamp(false, Kernel::NeighboursUpdate);
  // Conditional passes are dispatched directly (-1), the others from their slots.
  const std::vector<Pass> grid = grid_build_passes(p);
  const int grid_first = conditional_ ? -1 : 0;
  const int build_first = conditional_ ? -1 : static_cast<int>(grid.size());
  if (conditional_) gated(cb, true);
  stamp(true, Kernel::GridBuild);
  record_passes(cb, grid, p, grid_first);
  barrier(cb);
  stamp(false, Kernel::GridBuild);
  stamp(true, Kernel::NeighboursBuild);
  record_passes(cb, neighbours_build_passes(p), p, build_first);
  if (conditional_) gated(cb, false);
  barrier(cb, conditional_ ? Sync::AfterPredicate : Sync::Compute);
  stamp(false, Kernel::NeighboursBuild);
}

void VulkanDevice::record_neighbours_update(VkCommandBuffer cb, const shared::StepParams& p) const {
  std::uint32_t query = 0;
  record_neighbours_update(cb, p, nullptr, query);
}

}  // namespace motes::vulkan
