// The Vulkan compute backend: every kernel family as GLSL compute shaders over the shared physics
// headers. State stays on the GPU; kernel calls are queued and recorded into command buffers that
// are cached and replayed (a step's families are recorded once, 16 steps back to back in a command
// buffer), and the host waits only in read(), write(), synchronize() and check_guards().
#pragma once

#include <volk.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "motes/backend/device.h"
#include "motes/backend/kernel_queue.h"
#include "shader_stats.h"
#include "shared/common.h"
#include "vulkan_bindings.h"
#include "vulkan_context.h"
#include "vulkan_shaders.h"

namespace motes::vulkan {

/// The passes of families that need more than one pipeline, each a shader of its own
/// (shaders/FAMILY_PASS.comp), before the family's own shader (shaders/FAMILY.comp).
#define MOTES_VULKAN_PASSES(X)                      \
  X(GridBuildClear, grid_build_clear)               \
  X(GridBuildCount, grid_build_count)               \
  X(GridBuildScanBlock, grid_build_scan_block)      \
  X(GridBuildScanAdd, grid_build_scan_add)          \
  X(GridBuildScatter, grid_build_scatter)           \
  X(NeighboursBuildBegin, neighbours_build_begin)   \
  X(NeighboursUpdateSmall, neighbours_update_small) \
  X(ImpulsesApplyWide, impulses_apply_wide)         \
  X(ContactsComputeShift, contacts_compute_shift)

/// The compute pipelines: one per kernel family (motes/backend/kernels.h), whose shader is
/// shaders/NAME.comp, then the extra passes.
enum class Pipeline : std::uint32_t {
#define MOTES_FAMILY_PIPELINE(E, name, reads, writes) E,
  MOTES_KERNELS(MOTES_FAMILY_PIPELINE)
#undef MOTES_FAMILY_PIPELINE
#define MOTES_PASS_PIPELINE(E, name) E,
      MOTES_VULKAN_PASSES(MOTES_PASS_PIPELINE)
#undef MOTES_PASS_PIPELINE
          Count
};
constexpr std::size_t kPipelineCount = static_cast<std::size_t>(Pipeline::Count);
constexpr std::size_t kBindingCount = B_COUNT;

/// Push constants of every dispatch: the step's parameters and the pass's own four values.
struct PushConstants {
  shared::StepParams params;
  std::uint32_t args[4];
};
// 128 bytes: the most push constants every Vulkan device takes (maxPushConstantsSize >= 128).
static_assert(sizeof(PushConstants) == 128, "PushConstants layout");

class VulkanDevice final : public Device {
 public:
  /// One queued kernel call.
  using Op = KernelCall;

  /// Creates the logical device on `physical` (an index into instance->devices()).
  static Result<std::unique_ptr<VulkanDevice>> create(std::shared_ptr<Instance> instance,
                                                      int physical);
  /// On a program's device (motes/vulkan_interop.h: open_vulkan_device checked the handles):
  /// its queue `index` of `family`; the program's device and instance are never destroyed here.
  static Result<std::unique_ptr<VulkanDevice>> adopt(std::shared_ptr<Instance> instance,
                                                     int physical, VkDevice device,
                                                     std::uint32_t family, std::uint32_t index,
                                                     bool memory_budget);
  ~VulkanDevice() override;

  /// Made by adopt(): the buffers live on the program's device.
  [[nodiscard]] bool on_program_device() const { return !owns_device_; }
  /// The VkBuffer of `b` and the bytes of its data.
  [[nodiscard]] VkBuffer buffer_handle(Buffer b) const {
    return buffers_[static_cast<std::size_t>(b)].buffer;
  }
  [[nodiscard]] VkDeviceSize buffer_bytes(Buffer b) const {
    return buffers_[static_cast<std::size_t>(b)].data_bytes;
  }

  [[nodiscard]] const DeviceInfo& info() const override { return info_; }
  [[nodiscard]] std::uint64_t required_bytes(const Sizes& sizes) const override;
  [[nodiscard]] std::uint64_t available_bytes() const override;
  [[nodiscard]] BufferSize largest_buffer(const Sizes& sizes) const override;
  [[nodiscard]] BufferLimit buffer_limit() const override;
  Status allocate(const Sizes& sizes) override;
  Status write(Buffer b, const void* src, std::size_t bytes) override;
  Status write_at(Buffer b, std::size_t offset, const void* src, std::size_t bytes) override;
  Status read(Buffer b, void* dst, std::size_t bytes) override;

  void enqueue(Kernel k, const shared::StepParams& p) override;

  Status synchronize() override;
  Status check_guards() override;
  void set_timing(bool on) override { timing_ = on; }
  [[nodiscard]] KernelTimes kernel_times() const override { return times_; }
  void reset_kernel_times() override { times_ = {}; }

 private:
  /// Bytes after every buffer's data that hold the guard pattern.
  static constexpr VkDeviceSize kGuardBytes = 64;
  static constexpr std::uint32_t kGuardWord = 0xA5A5A5A5u;

  struct GpuBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize data_bytes = 0;    ///< what the kernels may touch; the guard words follow
    VkDeviceSize memory_bytes = 0;  ///< the allocation's size (vkGetBufferMemoryRequirements)
    void* mapped = nullptr;         ///< host-visible buffers only (staging)
  };
  /// One dispatch: a pipeline, its workgroups and the pass's own arguments.
  struct Pass {
    Pipeline pipeline;
    std::uint64_t groups;
    std::uint32_t args[4];
  };
  /// A recorded command buffer and the calls it runs.
  struct Recording {
    std::vector<Op> ops;
    VkCommandBuffer commands = VK_NULL_HANDLE;
  };

  VulkanDevice() = default;
  Status init(std::shared_ptr<Instance> instance, int physical);
  /// After device_ exists: the queue of physical_.compute_family, command pool, fence, pipelines.
  Status init_queue(std::uint32_t queue_index);
  Status create_pipelines();
  void release_buffers();
  Status create_buffer(GpuBuffer& out, VkDeviceSize data_bytes, bool host_visible,
                       const char* name);
  void destroy_buffer(GpuBuffer& b);
  Status ensure_staging(VkDeviceSize bytes);

  // Queue and replay (vulkan_record.cpp).
  /// Submits every queued call, replaying a cached recording when the calls repeat one.
  Status flush();
  /// A new primary command buffer, begun with `usage`.
  Result<VkCommandBuffer> begin_commands(VkCommandBufferUsageFlags usage);
  /// Records `ops` (with timestamps when `timing`) into a new primary command buffer. With
  /// timing, `spans` receives the kernel family of each pair of timestamps, in order.
  Result<VkCommandBuffer> record(const std::vector<Op>& ops, bool timing,
                                 std::vector<Kernel>* spans = nullptr);
  /// Timestamps a timed recording of `ops` writes (NeighboursUpdate: three pairs).
  static std::uint32_t timestamps_for(const std::vector<Op>& ops);
  /// Ends a recording: its error, or that of a pipeline it needed (pipeline_error_).
  Status end_recording(VkCommandBuffer cb);
  Status submit_and_wait(const VkCommandBuffer* commands, std::uint32_t count);
  /// Runs a one-off command buffer filled by `fill` and waits for it.
  Status run_once(const std::function<void(VkCommandBuffer)>& fill);
  Status check(VkResult r, const char* what);
  Status validation_status();
  void free_recordings();

  // Recording helpers shared by the kernel files.
  /// What a barrier makes visible: compute writes to the next dispatch (between passes), also to
  /// the indirect arguments read by the next dispatches (after neighbours_update.comp), or
  /// everything to everything, transfers and the host included (where a command buffer ends);
  /// Begin is All after begin_stages_ (where a command buffer starts); Predicate also to the
  /// conditional rendering that reads the rebuild's gate word (after a rebuild's decision), and
  /// AfterPredicate waits for that read too (after the passes it gated).
  enum class Sync { Compute, Indirect, All, Begin, Predicate, AfterPredicate };
  void barrier(VkCommandBuffer cb, Sync sync = Sync::Compute) const;
  /// Binds a pipeline, its descriptor set and the push constants.
  void bind(VkCommandBuffer cb, Pipeline pipeline, const PushConstants& push) const;
  /// Pipeline i, created from its shader at the first call; VK_NULL_HANDLE (and pipeline_error_
  /// set) when that fails.
  VkPipeline pipeline_at(std::size_t i) const;
  void dispatch(VkCommandBuffer cb, Pipeline pipeline, const shared::StepParams& p,
                std::uint64_t threads, std::uint32_t a0 = 0, std::uint32_t a1 = 0,
                std::uint32_t a2 = 0, std::uint32_t a3 = 0) const;
  void dispatch_groups(VkCommandBuffer cb, Pipeline pipeline, const shared::StepParams& p,
                       std::uint64_t groups, const std::uint32_t args[4]) const;
  /// Workgroups of a dispatch as (x, y, 1): more than max_groups_x_ go as a 2D grid.
  [[nodiscard]] std::array<std::uint32_t, 3> group_grid(std::uint64_t groups) const;
  /// Records passes with a barrier between each two; `indirect_first` >= 0: dispatched
  /// indirectly from B_INDIRECT_ARGS, pass k from slot indirect_first + k (a conditional rebuild).
  void record_passes(VkCommandBuffer cb, const std::vector<Pass>& passes,
                     const shared::StepParams& p, int indirect_first = -1) const;
  /// The passes of grid_build and of neighbours_build for these parameters.
  [[nodiscard]] std::vector<Pass> grid_build_passes(const shared::StepParams& p) const;
  [[nodiscard]] std::vector<Pass> neighbours_build_passes(const shared::StepParams& p) const;
  VkBuffer buffer(std::uint32_t binding) const { return buffers_[binding].buffer; }

  // One per kernel family, each in the file of the family's name. record_neighbours_update
  // records timestamps around its parts when `spans` is given (timing).
  void record_neighbours_update(VkCommandBuffer cb, const shared::StepParams& p,
                                std::vector<Kernel>* spans, std::uint32_t& query) const;
  // (the others, generated from the list: record_grid_build, record_contacts_compute...)
#define MOTES_RECORD_DECLARATION(E, name, reads, writes) \
  void record_##name(VkCommandBuffer cb, const shared::StepParams& p) const;
  MOTES_KERNELS(MOTES_RECORD_DECLARATION)
#undef MOTES_RECORD_DECLARATION
  /// Records one call of family k (not neighbours_update) by its record_NAME.
  void record(VkCommandBuffer cb, Kernel k, const shared::StepParams& p) const;

  std::shared_ptr<Instance> instance_;
  PhysicalDevice physical_;
  DeviceInfo info_;
  VkDevice device_ = VK_NULL_HANDLE;
  bool owns_device_ = true;  ///< false: a program's device (adopt)
  /// The first scope of the barrier that starts every command buffer: motes' own compute and
  /// transfers; on a program's device every command before it on the queue, so that a program's
  /// draw reading the particle buffers is done before a step writes them (vulkan_interop.h).
  VkPipelineStageFlags begin_stages_ =
      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkQueryPool queries_ = VK_NULL_HANDLE;
  std::uint32_t query_capacity_ = 0;
  // Per pipeline: the bindings its shader uses (bit k = binding k), and a descriptor set of
  // only those (create_pipelines).
  std::array<std::uint64_t, kPipelineCount> used_bindings_{};
  std::array<VkDescriptorSetLayout, kPipelineCount> set_layouts_{};
  std::array<VkPipelineLayout, kPipelineCount> pipeline_layouts_{};
  std::array<VkDescriptorSet, kPipelineCount> sets_{};
  VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
  /// On a CPU device created at a pipeline's first bind (pipeline_at()): a run compiles only the
  /// shaders it uses (lavapipe took 0.3 to 0.4 s to compile all of them, most of a conformance
  /// case's time); on a GPU all when the device opens (create_pipelines), so no step waits.
  mutable std::array<VkPipeline, kPipelineCount> pipelines_{};
  std::array<const Shader*, kPipelineCount> shaders_{};
  /// The first failure to create one while recording (record() and run_once() return it).
  mutable Status pipeline_error_;
  VkPhysicalDeviceMemoryProperties memory_{};
  /// VK_EXT_memory_budget is enabled: available_bytes() reads the heaps' budgets and usage.
  bool memory_budget_ = false;
  /// VK_EXT_conditional_rendering is on (the device has it and MOTES_VULKAN_NO_CONDITIONAL is not
  /// 1): a step without a rebuild skips the rebuild's dispatches instead of dispatching them empty
  /// (neighbours_update.cpp).
  bool conditional_ = false;
  /// Begins (vkCmdBeginConditionalRenderingEXT on the rebuild's gate word) or ends the part of a
  /// command buffer whose dispatches run only when the step rebuilds.
  void gated(VkCommandBuffer cb, bool begin) const;
  /// MOTES_VULKAN_SHADER_STATS: each pipeline's statistics as it is made (shader_stats.h).
  ShaderStats shader_stats_;

  Sizes sizes_;
  bool allocated_ = false;
  /// The most and the fewest particles a body has (0: not known: BodyFirst not written whole);
  /// bodies of kWideBodyParticles (four chunks of shared/impulse.h: MOTES_BODY_CHUNK) or more take
  /// impulses_apply_wide.comp, the others impulses_apply.comp (impulses_apply.cpp).
  shared::uint largest_body_ = 0;
  shared::uint smallest_body_ = 0;
  static constexpr shared::uint kWideBodyParticles = 256;
  std::array<GpuBuffer, kBindingCount> buffers_{};
  GpuBuffer staging_;
  /// Scan levels of the grid build: offset and count of each level's values.
  struct ScanLevel {
    std::uint32_t in_scratch, offset, count, sums_offset;
  };
  std::vector<ScanLevel> scan_levels_;
  /// Passes of a conditional rebuild (grid_build then neighbours_build, for the allocated sizes):
  /// slots of B_INDIRECT_ARGS, whose template follows them.
  std::uint32_t rebuild_passes_ = 0;
  /// The largest grid table (buckets) whose conditional rebuild is neighbours_update_small.glsl's
  /// one workgroup and a gated neighbours_build (MOTES_VULKAN_SMALL_REBUILD). By default
  /// kSmallRebuildTable on a GPU (16,384 particles: on an H200 a step without a build takes 16
  /// against 27 us, a build about 80 against 30: docs/benchmarks.md), never on a CPU device
  /// (lavapipe runs a workgroup on one thread).
  static constexpr std::uint32_t kSmallRebuildTable = 65536;
  std::uint32_t small_rebuild_table_ = 0;
  /// That workgroup's size: 1,024 invocations, or the device's most if it allows fewer.
  [[nodiscard]] std::uint32_t small_rebuild_threads() const {
    return std::max<std::uint32_t>(WORKGROUP_SIZE, std::min(1024u, physical_.max_workgroup_x));
  }
  /// The word of B_INDIRECT_ARGS that gates that neighbours_build: after the template.
  [[nodiscard]] std::uint32_t rebuild_gate_word() const { return rebuild_passes_ * 8; }

  /// Workgroups per dispatch dimension: 65,535 (Vulkan's guaranteed minimum), or less when
  /// MOTES_VULKAN_MAX_GROUPS_X says so (tests use it to exercise the 2D dispatch on small sizes).
  std::uint64_t max_groups_x_ = 65535;
  /// The neighbour list's columns per storage buffer (0: one buffer holds them all), set by
  /// allocate; at most list_columns_cap_ columns a block when set (MOTES_VULKAN_LIST_COLUMNS, so
  /// that tests reach the split list at small sizes).
  std::uint32_t list_columns_ = 0;
  std::uint32_t list_columns_cap_ = 0;
  /// Columns per block of the neighbour list for these sizes: 0 when one storage buffer holds the
  /// whole list, else as many as one buffer holds, and at least K / NEIGHBOUR_LIST_BLOCKS.
  [[nodiscard]] std::uint32_t list_columns(const Sizes& sizes) const;
  /// The column block a binding holds (-1: not the list's).
  static int list_block(std::uint32_t binding);
  static VkDeviceSize list_block_bytes(const Sizes& sizes, std::uint32_t columns,
                                       std::uint32_t block);
  /// Where bytes [offset, offset + bytes) of buffer b live: binding, offset there, offset in the
  /// caller's bytes, length (the neighbour list's column blocks are consecutive ranges of it).
  struct Piece {
    std::uint32_t binding;
    VkDeviceSize offset, at, bytes;
  };
  [[nodiscard]] std::vector<Piece> pieces(Buffer b, VkDeviceSize offset, VkDeviceSize bytes) const;
  /// The bytes of b's data (the neighbour list: of every block).
  [[nodiscard]] VkDeviceSize data_bytes(Buffer b) const;
  bool use_subgroups_ = false;  ///< the subgroup-arithmetic variant of the block scan
  std::vector<Op> pending_;
  std::vector<Recording> recordings_;
  /// Runs `times` times the recording of `cycles` copies of `cycle` (made at the first call, then
  /// cached in recordings_).
  Status replay(const std::vector<Op>& cycle, std::size_t cycles, std::size_t times);
  /// Cycles (steps) recorded back to back in one replayed command buffer, so that a command
  /// buffer's start and end (its barriers order everything, the host included) come once per this
  /// many: on an H200 they cost about 8 us, a third of a 16,384-sphere step (docs/benchmarks.md).
  /// MOTES_VULKAN_CYCLES sets another count (1: a step a command buffer).
  static constexpr std::size_t kCyclesPerBuffer = 16;
  std::size_t cycles_per_buffer_ = kCyclesPerBuffer;
  Status error_;  ///< sticky: the first failure (device lost, out of memory...)
  bool timing_ = false;
  KernelTimes times_;
};

}  // namespace motes::vulkan
