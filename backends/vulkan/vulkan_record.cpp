// Queueing, recording and replay. Kernel calls are queued; flush() finds the shortest cycle of
// calls that the queue repeats (a step: the five families, once per substep), records it
// kCyclesPerBuffer times back to back into a command buffer (and the remainder into another),
// caches them, and submits them as many times as the cycle repeats. A barrier starts and ends
// every command buffer and separates every dispatch, so each kernel sees all earlier writes.
// Timing records timestamps around every kernel family instead.
#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "vulkan_device.h"

namespace motes::vulkan {

namespace {

/// Recordings kept for replay; more than this and the least recently used is freed.
constexpr std::size_t kMaxRecordings = 8;
/// Timed runs record this many cycles per command buffer (two timestamps per kernel call each).
constexpr std::size_t kTimedCycles = 256;
/// Cycles per vkQueueSubmit (at least one command buffer) when a cycle is replayed many times.
constexpr std::size_t kSubmitBatch = 512;

}  // namespace

void VulkanDevice::enqueue(Kernel k, const shared::StepParams& p) {
  if (!allocated_) {
    if (error_) error_ = Status::error("vulkan: kernel launched before allocate");
    return;
  }
  // The halo entries and the partition's buffers exist only in runs over MPI ranks (Sizes): a
  // call beyond them would read and write past a buffer.
  if (std::string why = halo_launch_error(k, p, sizes_); !why.empty()) {
    if (error_) error_ = Status::error("vulkan: " + why);
    return;
  }
  // energy_reduce writes a block per 256 items: no more than EnergyPartials holds.
  if (std::string why = energy_launch_error(k, p, sizes_); !why.empty()) {
    if (error_) error_ = Status::error("vulkan: " + why);
    return;
  }
  pending_.push_back({k, p});
}

void VulkanDevice::record(VkCommandBuffer cb, Kernel k, const shared::StepParams& p) const {
  switch (k) {
    // neighbours_update records its own barriers and timestamps (record_neighbours_update).
#define MOTES_RECORD_CASE(E, name, reads, writes) \
  case Kernel::E:                                 \
    record_##name(cb, p);                         \
    break;
    MOTES_KERNELS(MOTES_RECORD_CASE)
#undef MOTES_RECORD_CASE
    case Kernel::Count:
      break;
  }
}

void VulkanDevice::barrier(VkCommandBuffer cb, Sync sync) const {
  VkMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  VkPipelineStageFlags src = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
  VkPipelineStageFlags dst = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
  if (sync == Sync::Indirect) {
    b.dstAccessMask |= VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
    dst |= VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT;
  } else if (sync == Sync::Predicate) {
    b.dstAccessMask |= VK_ACCESS_CONDITIONAL_RENDERING_READ_BIT_EXT;
    dst |= VK_PIPELINE_STAGE_CONDITIONAL_RENDERING_BIT_EXT;
  } else if (sync == Sync::AfterPredicate) {
    src |= VK_PIPELINE_STAGE_CONDITIONAL_RENDERING_BIT_EXT;
  } else if (sync == Sync::All || sync == Sync::Begin) {
    if (sync == Sync::Begin) src = begin_stages_;
    b.srcAccessMask |= VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask |= VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                       VK_ACCESS_HOST_READ_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
    src |= VK_PIPELINE_STAGE_TRANSFER_BIT;
    dst |= VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT |
           VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT;
  }
  vkCmdPipelineBarrier(cb, src, dst, 0, 1, &b, 0, nullptr, 0, nullptr);
}

std::array<std::uint32_t, 3> VulkanDevice::group_grid(std::uint64_t groups) const {
  if (groups == 0) return {0, 0, 0};
  const std::uint64_t x = std::min<std::uint64_t>(groups, max_groups_x_);
  const std::uint64_t y = (groups + x - 1) / x;
  return {static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), 1};
}

void VulkanDevice::record_passes(VkCommandBuffer cb, const std::vector<Pass>& passes,
                                 const shared::StepParams& p, int indirect_first) const {
  for (std::size_t k = 0; k < passes.size(); ++k) {
    const Pass& pass = passes[k];
    if (k > 0) barrier(cb);
    if (indirect_first < 0) {
      dispatch_groups(cb, pass.pipeline, p, pass.groups, pass.args);
    } else {
      PushConstants push{};
      push.params = p;
      std::copy(pass.args, pass.args + 4, push.args);
      bind(cb, pass.pipeline, push);
      const auto slot = static_cast<VkDeviceSize>(indirect_first) + k;
      vkCmdDispatchIndirect(cb, buffer(B_INDIRECT_ARGS), slot * 16);
    }
  }
}

void VulkanDevice::gated(VkCommandBuffer cb, bool begin) const {
  if (!begin) {
    vkCmdEndConditionalRenderingEXT(cb);
    return;
  }
  VkConditionalRenderingBeginInfoEXT info{};
  info.sType = VK_STRUCTURE_TYPE_CONDITIONAL_RENDERING_BEGIN_INFO_EXT;
  info.buffer = buffer(B_INDIRECT_ARGS);
  info.offset = VkDeviceSize{rebuild_gate_word()} * 4;
  vkCmdBeginConditionalRenderingEXT(cb, &info);
}

void VulkanDevice::bind(VkCommandBuffer cb, Pipeline pipeline, const PushConstants& push) const {
  const auto i = static_cast<std::size_t>(pipeline);
  const VkPipeline pipe = pipeline_at(i);
  if (pipe == VK_NULL_HANDLE) return;  // recorded, never submitted: record() and run_once() fail
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layouts_[i], 0, 1, &sets_[i],
                          0, nullptr);
  PushConstants q = push;
  q.params.neighbour_columns = list_columns_;  // the list's blocks (kernel_common.glsl: list_entry)
  vkCmdPushConstants(cb, pipeline_layouts_[i], VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(q), &q);
}

void VulkanDevice::dispatch_groups(VkCommandBuffer cb, Pipeline pipeline,
                                   const shared::StepParams& p, std::uint64_t groups,
                                   const std::uint32_t args[4]) const {
  if (groups == 0) return;
  PushConstants push{};
  push.params = p;
  std::copy(args, args + 4, push.args);
  bind(cb, pipeline, push);
  // More than 65,535 workgroups (the smallest limit Vulkan allows per dimension) go as a 2D grid;
  // shaders flatten it (kernel_common.glsl: flat_group) and skip the padding groups.
  const std::array<std::uint32_t, 3> grid = group_grid(groups);
  vkCmdDispatch(cb, grid[0], grid[1], grid[2]);
}

void VulkanDevice::dispatch(VkCommandBuffer cb, Pipeline pipeline, const shared::StepParams& p,
                            std::uint64_t threads, std::uint32_t a0, std::uint32_t a1,
                            std::uint32_t a2, std::uint32_t a3) const {
  const std::uint32_t args[4] = {a0, a1, a2, a3};
  dispatch_groups(cb, pipeline, p, (threads + WORKGROUP_SIZE - 1) / WORKGROUP_SIZE, args);
}

Result<VkCommandBuffer> VulkanDevice::begin_commands(VkCommandBufferUsageFlags usage) {
  VkCommandBufferAllocateInfo alloc{};
  alloc.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  if (Status s = check(vkAllocateCommandBuffers(device_, &alloc, &cb), "vkAllocateCommandBuffers");
      !s) {
    return s;
  }
  VkCommandBufferBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin.flags = usage;
  if (Status s = check(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer"); !s) {
    vkFreeCommandBuffers(device_, pool_, 1, &cb);
    return s;
  }
  return cb;
}

std::uint32_t VulkanDevice::timestamps_for(const std::vector<Op>& ops) {
  std::uint32_t count = 0;
  for (const Op& op : ops) count += op.kernel == Kernel::NeighboursUpdate ? 6 : 2;
  return count;
}

Result<VkCommandBuffer> VulkanDevice::record(const std::vector<Op>& ops, bool timing,
                                             std::vector<Kernel>* spans) {
  // A replayed cycle is listed several times in one submission.
  Result<VkCommandBuffer> began = begin_commands(VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT);
  if (!began) return began;
  VkCommandBuffer cb = began.value();
  if (timing) vkCmdResetQueryPool(cb, queries_, 0, timestamps_for(ops));
  barrier(cb, Sync::Begin);
  std::uint32_t q = 0;
  for (std::size_t i = 0; i < ops.size(); ++i) {
    const shared::StepParams& p = ops[i].params;
    if (ops[i].kernel == Kernel::NeighboursUpdate) {  // its own barriers and timestamps
      record_neighbours_update(cb, p, timing ? spans : nullptr, q);
      continue;
    }
    if (timing) {
      vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, queries_, q++);
      if (spans != nullptr) spans->push_back(ops[i].kernel);
    }
    record(cb, ops[i].kernel, p);
    barrier(cb);
    if (timing) vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, queries_, q++);
  }
  barrier(cb, Sync::All);
  Status s = end_recording(cb);
  if (!s) {
    vkFreeCommandBuffers(device_, pool_, 1, &cb);
    return s;
  }
  return cb;
}

Status VulkanDevice::end_recording(VkCommandBuffer cb) {
  Status s = check(vkEndCommandBuffer(cb), "vkEndCommandBuffer");
  if (s && !pipeline_error_) {  // a pipeline this recording binds could not be created
    if (error_) error_ = pipeline_error_;
    s = pipeline_error_;
  }
  return s;
}

Status VulkanDevice::submit_and_wait(const VkCommandBuffer* commands, std::uint32_t count) {
  VkSubmitInfo submit{};
  submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  submit.commandBufferCount = count;
  submit.pCommandBuffers = commands;
  if (Status s = check(vkResetFences(device_, 1, &fence_), "vkResetFences"); !s) return s;
  if (Status s = check(vkQueueSubmit(queue_, 1, &submit, fence_), "vkQueueSubmit"); !s) return s;
  return check(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
}

Status VulkanDevice::run_once(const std::function<void(VkCommandBuffer)>& fill) {
  if (!error_) return error_;
  Result<VkCommandBuffer> began = begin_commands(VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT);
  if (!began) return began.status();
  VkCommandBuffer cb = began.value();
  barrier(cb, Sync::Begin);
  fill(cb);
  barrier(cb, Sync::All);
  Status s = end_recording(cb);
  if (s) s = submit_and_wait(&cb, 1);
  vkFreeCommandBuffers(device_, pool_, 1, &cb);
  return s;
}

void VulkanDevice::free_recordings() {
  for (Recording& r : recordings_) vkFreeCommandBuffers(device_, pool_, 1, &r.commands);
  recordings_.clear();
}

Status VulkanDevice::flush() {
  if (!error_) {
    pending_.clear();
    return error_;
  }
  if (pending_.empty()) return Status::ok();
  std::vector<Op> ops;
  ops.swap(pending_);

  // The shortest cycle that the queued calls repeat.
  const std::size_t n = ops.size();
  const std::size_t period = repeating_period(ops);
  const std::vector<Op> cycle(ops.begin(), ops.begin() + static_cast<std::ptrdiff_t>(period));
  std::size_t reps = n / period;

  if (timing_) {
    // Timed: record up to kTimedCycles cycles per command buffer with timestamps around every
    // call, run it, read the timestamps. Not cached: timing is for benchmarks.
    const bool stamps = physical_.timestamp_bits > 0;
    while (reps > 0) {
      const std::size_t k = std::min(reps, kTimedCycles);
      std::vector<Op> batch;
      batch.reserve(k * period);
      for (std::size_t r = 0; r < k; ++r) batch.insert(batch.end(), cycle.begin(), cycle.end());
      const std::uint32_t queries = timestamps_for(batch);
      if (stamps && queries > query_capacity_) {
        if (queries_ != VK_NULL_HANDLE) vkDestroyQueryPool(device_, queries_, nullptr);
        VkQueryPoolCreateInfo qi{};
        qi.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
        qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
        qi.queryCount = queries;
        if (Status s =
                check(vkCreateQueryPool(device_, &qi, nullptr, &queries_), "vkCreateQueryPool");
            !s) {
          return s;
        }
        query_capacity_ = queries;
      }
      std::vector<Kernel> spans;
      Result<VkCommandBuffer> cb = record(batch, stamps, &spans);
      if (!cb) return cb.status();
      Status s = submit_and_wait(&cb.value(), 1);
      if (s && stamps) {
        std::vector<std::uint64_t> t(queries);
        s = check(vkGetQueryPoolResults(device_, queries_, 0, queries, t.size() * 8, t.data(), 8,
                                        VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                  "vkGetQueryPoolResults");
        const std::uint64_t mask = physical_.timestamp_bits >= 64
                                       ? ~std::uint64_t{0}
                                       : (std::uint64_t{1} << physical_.timestamp_bits) - 1;
        for (std::size_t i = 0; s && i < spans.size(); ++i) {
          const std::uint64_t ticks = (t[2 * i + 1] - t[2 * i]) & mask;
          const auto kernel = static_cast<std::size_t>(spans[i]);
          times_.seconds[kernel] += static_cast<double>(ticks) *
                                    static_cast<double>(physical_.timestamp_period_ns) * 1e-9;
          times_.launches[kernel] += 1;
        }
      }
      vkFreeCommandBuffers(device_, pool_, 1, &cb.value());
      if (!s) return s;
      reps -= k;
    }
    return Status::ok();
  }

  // Replay: the cycle recorded cycles_per_buffer_ times back to back, made once, then the
  // remainder's recording.
  const std::size_t per = std::min(reps, cycles_per_buffer_);
  if (Status s = replay(cycle, per, reps / per); !s) return s;
  if (reps % per != 0) return replay(cycle, reps % per, 1);
  return Status::ok();
}

Status VulkanDevice::replay(const std::vector<Op>& cycle, std::size_t cycles, std::size_t times) {
  std::vector<Op> ops;
  ops.reserve(cycle.size() * cycles);
  for (std::size_t r = 0; r < cycles; ++r) ops.insert(ops.end(), cycle.begin(), cycle.end());
  auto found = std::find_if(recordings_.begin(), recordings_.end(),
                            [&](const Recording& r) { return same_calls(r.ops, ops); });
  if (found == recordings_.end()) {
    if (recordings_.size() >= kMaxRecordings) {  // nothing is in flight between flushes
      vkFreeCommandBuffers(device_, pool_, 1, &recordings_.front().commands);
      recordings_.erase(recordings_.begin());
    }
    Result<VkCommandBuffer> cb = record(ops, false);
    if (!cb) return cb.status();
    recordings_.push_back({std::move(ops), cb.value()});
    found = recordings_.end() - 1;
  } else if (found + 1 != recordings_.end()) {  // the last used goes last: evicted last
    std::rotate(found, found + 1, recordings_.end());
    found = recordings_.end() - 1;
  }
  const std::size_t batch = std::max<std::size_t>(1, kSubmitBatch / cycles);
  const std::vector<VkCommandBuffer> list(std::min(times, batch), found->commands);
  while (times > 0) {
    const std::size_t k = std::min(times, batch);
    if (Status s = submit_and_wait(list.data(), static_cast<std::uint32_t>(k)); !s) return s;
    times -= k;
  }
  return Status::ok();
}

}  // namespace motes::vulkan
