// The Vulkan compute backend: every kernel family as GLSL compute shaders over the shared physics
// headers. State stays on the GPU; kernel calls are queued and recorded into command buffers that
// are cached and replayed (a step's five families are recorded once), and the host waits only in
// read(), write(), synchronize() and check_guards().
#pragma once

#include <volk.h>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "motes/backend/device.h"
#include "motes/backend/kernel_queue.h"
#include "shared/common.h"
#include "vulkan_bindings.h"
#include "vulkan_context.h"

namespace motes::vulkan {

/// The compute pipelines, one per shader in shaders/*.comp.
enum class Pipeline : std::uint32_t {
  GridBuildCount,
  GridBuildScanBlock,
  GridBuildScanAdd,
  GridBuildScatter,
  GridBuildPlace,
  ContactsCompute,
  BodiesReduce,
  BodiesIntegrate,
  ParticlesUpdate,
  Count
};
constexpr std::size_t kPipelineCount = static_cast<std::size_t>(Pipeline::Count);
constexpr std::size_t kBindingCount = B_COUNT;

/// Push constants of every dispatch: the step's parameters and the pass's own four values.
struct PushConstants {
  shared::StepParams params;
  std::uint32_t args[4];
};
static_assert(sizeof(PushConstants) == 64, "PushConstants layout");

class VulkanDevice final : public Device {
 public:
  /// One queued kernel call.
  using Op = KernelCall;

  /// Creates the logical device on `physical` (an index into instance->devices()).
  static Result<std::unique_ptr<VulkanDevice>> create(std::shared_ptr<Instance> instance,
                                                      int physical);
  ~VulkanDevice() override;

  [[nodiscard]] const DeviceInfo& info() const override { return info_; }
  Status allocate(const Sizes& sizes) override;
  Status write(Buffer b, const void* src, std::size_t bytes) override;
  Status read(Buffer b, void* dst, std::size_t bytes) override;

  void grid_build(const shared::StepParams& p) override;
  void contacts_compute(const shared::StepParams& p) override;
  void bodies_reduce(const shared::StepParams& p) override;
  void bodies_integrate(const shared::StepParams& p) override;
  void particles_update(const shared::StepParams& p) override;

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
    VkDeviceSize data_bytes = 0;  ///< what the kernels may touch; the guard words follow
    void* mapped = nullptr;       ///< host-visible buffers only (staging)
  };
  /// A recorded command buffer and the calls it runs.
  struct Recording {
    std::vector<Op> ops;
    VkCommandBuffer commands = VK_NULL_HANDLE;
  };

  VulkanDevice() = default;
  Status init(std::shared_ptr<Instance> instance, int physical);
  Status create_pipelines();
  void release_buffers();
  Status create_buffer(GpuBuffer& out, VkDeviceSize data_bytes, bool host_visible,
                       const char* name);
  void destroy_buffer(GpuBuffer& b);
  Status ensure_staging(VkDeviceSize bytes);

  // Queue and replay (vulkan_record.cpp).
  void enqueue(Kernel k, const shared::StepParams& p);
  /// Submits every queued call, replaying a cached recording when the calls repeat one.
  Status flush();
  /// A new primary command buffer, begun with `usage`.
  Result<VkCommandBuffer> begin_commands(VkCommandBufferUsageFlags usage);
  /// Records `ops` (with timestamps when `timing`) into a new primary command buffer.
  Result<VkCommandBuffer> record(const std::vector<Op>& ops, bool timing);
  Status submit_and_wait(const VkCommandBuffer* commands, std::uint32_t count);
  /// Runs a one-off command buffer filled by `fill` and waits for it.
  Status run_once(const std::function<void(VkCommandBuffer)>& fill);
  Status check(VkResult r, const char* what);
  Status validation_status();
  void free_recordings();

  // Recording helpers shared by the kernel files.
  void barrier(VkCommandBuffer cb) const;
  void dispatch(VkCommandBuffer cb, Pipeline pipeline, const shared::StepParams& p,
                std::uint64_t threads, std::uint32_t a0 = 0, std::uint32_t a1 = 0,
                std::uint32_t a2 = 0, std::uint32_t a3 = 0) const;
  void dispatch_groups(VkCommandBuffer cb, Pipeline pipeline, const shared::StepParams& p,
                       std::uint64_t groups, const std::uint32_t args[4]) const;
  VkBuffer buffer(std::uint32_t binding) const { return buffers_[binding].buffer; }

  // One per kernel family, each in the file of the family's name.
  void record_grid_build(VkCommandBuffer cb, const shared::StepParams& p) const;
  void record_contacts_compute(VkCommandBuffer cb, const shared::StepParams& p) const;
  void record_bodies_reduce(VkCommandBuffer cb, const shared::StepParams& p) const;
  void record_bodies_integrate(VkCommandBuffer cb, const shared::StepParams& p) const;
  void record_particles_update(VkCommandBuffer cb, const shared::StepParams& p) const;

  std::shared_ptr<Instance> instance_;
  PhysicalDevice physical_;
  DeviceInfo info_;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkQueryPool queries_ = VK_NULL_HANDLE;
  std::uint32_t query_capacity_ = 0;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout pipeline_layout_ = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  std::array<VkPipeline, kPipelineCount> pipelines_{};
  VkPhysicalDeviceMemoryProperties memory_{};

  Sizes sizes_;
  bool allocated_ = false;
  std::array<GpuBuffer, kBindingCount> buffers_{};
  GpuBuffer staging_;
  /// Scan levels of the grid build: offset and count of each level's values.
  struct ScanLevel {
    std::uint32_t in_scratch, offset, count, sums_offset;
  };
  std::vector<ScanLevel> scan_levels_;

  /// Workgroups per dispatch dimension: 65,535 (Vulkan's guaranteed minimum), or less when
  /// MOTES_VULKAN_MAX_GROUPS_X says so (tests use it to exercise the 2D dispatch on small sizes).
  std::uint64_t max_groups_x_ = 65535;
  bool use_subgroups_ = false;  ///< the subgroup-arithmetic variant of the block scan
  std::vector<Op> pending_;
  std::vector<Recording> recordings_;
  Status error_;  ///< sticky: the first failure (device lost, out of memory...)
  bool timing_ = false;
  KernelTimes times_;
};

}  // namespace motes::vulkan
