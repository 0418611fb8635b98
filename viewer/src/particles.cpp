// The sphere pipeline's instance buffers and colour rule, staged or zero copy (particles.h).
#include "particles.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "motes/vulkan_interop.h"
#include "painter.h"

namespace motes::viewer {

namespace {

constexpr VkDeviceSize kVec4 = sizeof(Vec4);
constexpr std::uint32_t kSpeedGroupSize = 256;  // speed_max.comp's local size
constexpr std::uint32_t kMaxGroups = 65535;     // it strides over the rest

}  // namespace

Particles::Particles(const Gpu& gpu)
    : gpu_(gpu),
      colors_(gpu, sizeof(ColorState),
              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT) {
  VkDescriptorSetLayoutBinding bindings[2]{};
  bindings[0].binding = 0;
  bindings[0].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  bindings[0].descriptorCount = 1;
  bindings[0].stageFlags = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_COMPUTE_BIT;
  bindings[1] = bindings[0];
  bindings[1].binding = 1;
  bindings[1].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  VkDescriptorSetLayoutCreateInfo set_info{};
  set_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  set_info.bindingCount = 2;
  set_info.pBindings = bindings;
  check(gpu_.vk.vkCreateDescriptorSetLayout(gpu_.device, &set_info, nullptr, &set_layout_),
        "vkCreateDescriptorSetLayout");
  const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2};
  VkDescriptorPoolCreateInfo pool_info{};
  pool_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  pool_info.maxSets = 1;
  pool_info.poolSizeCount = 1;
  pool_info.pPoolSizes = &size;
  check(gpu_.vk.vkCreateDescriptorPool(gpu_.device, &pool_info, nullptr, &pool_),
        "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo alloc{};
  alloc.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  alloc.descriptorPool = pool_;
  alloc.descriptorSetCount = 1;
  alloc.pSetLayouts = &set_layout_;
  check(gpu_.vk.vkAllocateDescriptorSets(gpu_.device, &alloc, &set_), "vkAllocateDescriptorSets");
  const VkDescriptorBufferInfo state{colors_.buffer, 0, sizeof(ColorState)};
  VkWriteDescriptorSet write{};
  write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
  write.dstSet = set_;
  write.dstBinding = 0;
  write.descriptorCount = 1;
  write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  write.pBufferInfo = &state;
  gpu_.vk.vkUpdateDescriptorSets(gpu_.device, 1, &write, 0, nullptr);
  write_colors(ColorState{});

  const VkPushConstantRange count{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(std::uint32_t)};
  VkPipelineLayoutCreateInfo layout{};
  layout.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  layout.setLayoutCount = 1;
  layout.pSetLayouts = &set_layout_;
  layout.pushConstantRangeCount = 1;
  layout.pPushConstantRanges = &count;
  check(gpu_.vk.vkCreatePipelineLayout(gpu_.device, &layout, nullptr, &speed_layout_),
        "vkCreatePipelineLayout");
  const VkShaderModule module = make_module(gpu_, "speed_max.comp");
  VkComputePipelineCreateInfo pipe{};
  pipe.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  pipe.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  pipe.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  pipe.stage.module = module;
  pipe.stage.pName = "main";
  pipe.layout = speed_layout_;
  const VkResult r =
      gpu_.vk.vkCreateComputePipelines(gpu_.device, VK_NULL_HANDLE, 1, &pipe, nullptr, &speed_max_);
  gpu_.vk.vkDestroyShaderModule(gpu_.device, module, nullptr);
  check(r, "vkCreateComputePipelines");
}

Particles::~Particles() {
  gpu_.vk.vkDeviceWaitIdle(gpu_.device);
  if (speed_max_ != VK_NULL_HANDLE) gpu_.vk.vkDestroyPipeline(gpu_.device, speed_max_, nullptr);
  if (speed_layout_ != VK_NULL_HANDLE) {
    gpu_.vk.vkDestroyPipelineLayout(gpu_.device, speed_layout_, nullptr);
  }
  if (pool_ != VK_NULL_HANDLE) gpu_.vk.vkDestroyDescriptorPool(gpu_.device, pool_, nullptr);
  if (set_layout_ != VK_NULL_HANDLE) {
    gpu_.vk.vkDestroyDescriptorSetLayout(gpu_.device, set_layout_, nullptr);
  }
}

void Particles::write_colors(const ColorState& state) {
  std::memcpy(colors_.mapped, &state, sizeof(state));
}

void Particles::detach() {
  if (!direct_) return;
  direct_.reset();
  per_device_.reset();
  shared_.reset();
  shared_sim_ = nullptr;
  count_ = 0;
  write_colors(ColorState{});  // staged, the colours come with the particles
}

const char* Particles::path() const {
  if (!direct_) return "staged";
  return shared_ ? "CUDA copy" : "zero copy";
}

void Particles::refresh() {
  if (shared_) shared_->copy(*shared_sim_);
}

void Particles::stage(Styler& styler, const Snapshot& frame) {
  detach();
  Instances instances;
  styler.instances(frame, instances);
  count_ = static_cast<std::uint32_t>(instances.spheres.size());
  const VkDeviceSize half = std::max<VkDeviceSize>(kVec4 * count_, 64);
  if (!staged_ || staged_->size < 2 * half) {
    staged_.reset();
    staged_ = std::make_unique<HostBuffer>(gpu_, 2 * (half + half / 4),
                                           VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  }
  staged_colors_offset_ = staged_->size / 2;
  if (count_ > 0) {
    auto* bytes = static_cast<unsigned char*>(staged_->mapped);
    std::memcpy(bytes, instances.spheres.data(), kVec4 * count_);
    std::memcpy(bytes + staged_colors_offset_, instances.colors.data(), kVec4 * count_);
  }
}

std::string Particles::attach(const Styler& styler, Simulation& sim, const Snapshot& first_frame) {
  detach();
  if (sim.device().info().backend == "vulkan") {
    Result<VulkanParticleBuffers> buffers = vulkan_particle_buffers(sim);
    if (!buffers) return buffers.message();
    use(styler, sim, first_frame, buffers.value());
    return {};
  }
  if (std::string why = CudaShare::why_not(gpu_, sim); !why.empty()) return why;
  const bool velocities = styler.color_state().mode != ColorState::kAttribute;
  try {
    shared_ = std::make_unique<CudaShare>(gpu_, sim, velocities);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  shared_sim_ = &sim;
  VulkanParticleBuffers buffers;
  buffers.positions.buffer = buffers.velocities.buffer = shared_->buffer();
  buffers.positions.count = buffers.velocities.count = sim.particle_count();
  buffers.positions.stride = buffers.velocities.stride = kVec4;
  buffers.positions.size = buffers.velocities.size = kVec4 * sim.particle_count();
  buffers.velocities.offset = shared_->velocities_offset();
  use(styler, sim, first_frame, buffers);
  return {};
}

void Particles::use(const Styler& styler, Simulation& sim, const Snapshot& first_frame,
                    const VulkanParticleBuffers& buffers) {
  const VulkanBufferRange& positions = buffers.positions;
  const VulkanBufferRange& velocities = buffers.velocities;
  staged_.reset();
  count_ = positions.count;
  Direct d;
  d.positions = positions.buffer;
  d.positions_offset = positions.offset;
  const ColorState state = styler.color_state();
  write_colors(state);
  if (state.mode == ColorState::kAttribute) {
    // Body and kind colours stay the same: once, in the device's particle order.
    const std::vector<Vec4> colors = styler.device_colors(first_frame, sim.scene_particle_order());
    if (!colors.empty()) {
      per_device_ = std::make_unique<DeviceBuffer>(gpu_, colors.data(), kVec4 * colors.size(),
                                                   VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
      d.attributes = per_device_->buffer;
    }
  } else {
    d.attributes = velocities.buffer;
    d.attributes_offset = velocities.offset;
    d.speed = state.mode == ColorState::kSpeed && count_ > 0;
    const VkDescriptorBufferInfo vel{velocities.buffer, velocities.offset, velocities.size};
    VkWriteDescriptorSet write{};
    write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    write.dstSet = set_;
    write.dstBinding = 1;
    write.descriptorCount = 1;
    write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    write.pBufferInfo = &vel;
    if (count_ > 0) gpu_.vk.vkUpdateDescriptorSets(gpu_.device, 1, &write, 0, nullptr);
  }
  direct_ = d;
}

void Particles::record_before(VkCommandBuffer cmd) const {
  if (!direct_ || count_ == 0) return;
  if (shared_) shared_->record_acquire(cmd);
  // motes' compute and transfer writes (submitted before on this queue), and the last frame's
  // reads of the running speed maximum, before this frame reads and updates them.
  VkMemoryBarrier after_motes{};
  after_motes.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  after_motes.srcAccessMask = kVulkanWriteAccess;
  after_motes.dstAccessMask =
      VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT | VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  gpu_.vk.vkCmdPipelineBarrier(cmd, kVulkanWriteStages | VK_PIPELINE_STAGE_VERTEX_SHADER_BIT,
                               VK_PIPELINE_STAGE_VERTEX_INPUT_BIT |
                                   VK_PIPELINE_STAGE_VERTEX_SHADER_BIT |
                                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                               0, 1, &after_motes, 0, nullptr, 0, nullptr);
  if (!direct_->speed) return;
  gpu_.vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, speed_max_);
  gpu_.vk.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, speed_layout_, 0, 1, &set_,
                                  0, nullptr);
  gpu_.vk.vkCmdPushConstants(cmd, speed_layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0,
                             sizeof(std::uint32_t), &count_);
  const std::uint32_t groups =
      std::min(kMaxGroups, (count_ + kSpeedGroupSize - 1) / kSpeedGroupSize);
  gpu_.vk.vkCmdDispatch(cmd, groups, 1, 1);
  VkMemoryBarrier to_vertices{};
  to_vertices.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  to_vertices.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  to_vertices.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
  gpu_.vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                               VK_PIPELINE_STAGE_VERTEX_SHADER_BIT, 0, 1, &to_vertices, 0, nullptr,
                               0, nullptr);
}

void Particles::record_draw(VkCommandBuffer cmd, VkPipelineLayout layout) const {
  if (count_ == 0) return;
  gpu_.vk.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, 0, 1, &set_, 0,
                                  nullptr);
  VkBuffer buffers[2];
  VkDeviceSize offsets[2];
  if (direct_) {
    buffers[0] = direct_->positions;
    offsets[0] = direct_->positions_offset;
    buffers[1] = direct_->attributes;
    offsets[1] = direct_->attributes_offset;
  } else {
    buffers[0] = buffers[1] = staged_->buffer;
    offsets[0] = 0;
    offsets[1] = staged_colors_offset_;
  }
  gpu_.vk.vkCmdBindVertexBuffers(cmd, 0, 2, buffers, offsets);
  gpu_.vk.vkCmdDraw(cmd, 4, count_, 0, 0);
}

void Particles::record_after(VkCommandBuffer cmd) const {
  if (shared_ && count_ > 0) shared_->record_release(cmd);
}

}  // namespace motes::viewer
