// VulkanDevice: logical device, pipelines, buffers with guard words, host transfers, and the
// backend entry points (list_devices, open_device). Queueing and replay: vulkan_record.cpp.
#include "vulkan_device.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "vulkan_backend.h"
#include "vulkan_shaders.h"

namespace motes::vulkan {

// Binding k of the descriptor set is motes::Buffer k (shaders/vulkan_bindings.h).
static_assert(B_PARTICLE_POS == static_cast<int>(Buffer::ParticlePos));
static_assert(B_PARTICLE_FORCE == static_cast<int>(Buffer::ParticleForce));
static_assert(B_BODY_POS == static_cast<int>(Buffer::BodyPos));
static_assert(B_BODY_FIRST == static_cast<int>(Buffer::BodyFirst));
static_assert(B_GRID_BUCKET == static_cast<int>(Buffer::GridBucket));
static_assert(B_GRID_CELL_START == static_cast<int>(Buffer::GridCellStart));
static_assert(B_SORTED_BODY == static_cast<int>(Buffer::SortedBody));
static_assert(B_NEIGHBOUR_LIST == static_cast<int>(Buffer::NeighbourList));
static_assert(B_NEIGHBOUR_STATE == static_cast<int>(Buffer::NeighbourState));
static_assert(B_CONTACT_LAWS == static_cast<int>(Buffer::ContactLaws));
static_assert(B_PLANES == static_cast<int>(Buffer::Planes));
static_assert(B_CONSTRAINTS == static_cast<int>(Buffer::Constraints));
static_assert(B_CONSTRAINT_COLOURS == static_cast<int>(Buffer::ConstraintColours));
static_assert(B_CLUSTERS == static_cast<int>(Buffer::Clusters));
static_assert(B_CLUSTER_GATHER == static_cast<int>(Buffer::ClusterGather));
static_assert(B_PARTICLE_MOMENT == static_cast<int>(Buffer::ParticleMoment));
static_assert(B_BODY_ANGVEL_START == static_cast<int>(Buffer::BodyAngVelStart));
static_assert(B_IMPULSE_STAMP == static_cast<int>(Buffer::ImpulseStamp));
static_assert(B_MOTION_CHECK == static_cast<int>(Buffer::MotionCheck));
static_assert(B_LINK_EXCLUSIONS == static_cast<int>(Buffer::LinkExclusions));
static_assert(B_HALO_INDEX == static_cast<int>(Buffer::HaloIndex));
static_assert(B_HALO_DATA == static_cast<int>(Buffer::HaloData));
static_assert(B_PARTITION_REF_POS == static_cast<int>(Buffer::PartitionRefPos));
static_assert(B_PARTITION_CHECK == static_cast<int>(Buffer::PartitionCheck));
static_assert(B_CONTACT_IMPULSE_SPLIT == static_cast<int>(Buffer::ContactImpulseSplit));
static_assert(B_BODY_POS_LOW == static_cast<int>(Buffer::BodyPosLow));
static_assert(B_BODY_VEL_PUSH == static_cast<int>(Buffer::BodyVelPush));
static_assert(B_BODY_ANGMOM_PUSH == static_cast<int>(Buffer::BodyAngMomPush));
static_assert(B_ENERGY_PARTIALS == static_cast<int>(Buffer::EnergyPartials));
static_assert(B_FLUID_STATE == static_cast<int>(Buffer::FluidState));
static_assert(B_FLUID_MATERIALS == static_cast<int>(Buffer::FluidMaterials));
static_assert(B_FLUID_VEL_OLD == static_cast<int>(Buffer::FluidVelOld));
static_assert(B_FLUID_AUX == static_cast<int>(Buffer::FluidAux));
static_assert(B_FLUID_NORMAL == static_cast<int>(Buffer::FluidNormal));
static_assert(B_GRID_ARRIVAL == static_cast<int>(Buffer::Count));

namespace {

// Each pipeline's shader (its file stem in shaders/), in Pipeline's order.
constexpr const char* kPipelineShaders[kPipelineCount] = {
#define MOTES_FAMILY_SHADER(E, name, reads, writes) #name,
    MOTES_KERNELS(MOTES_FAMILY_SHADER)
#undef MOTES_FAMILY_SHADER
#define MOTES_PASS_SHADER(E, name) #name,
        MOTES_VULKAN_PASSES(MOTES_PASS_SHADER)
#undef MOTES_PASS_SHADER
};

const char* binding_name(std::uint32_t binding) {
  if (binding < kBufferCount) return buffer_name(static_cast<Buffer>(binding));
  switch (binding) {
    case B_GRID_ARRIVAL:
      return "GridArrival (scratch)";
    case B_GRID_UNSORTED:
      return "GridUnsorted (scratch)";
    case B_SCAN_SCRATCH:
      return "ScanScratch (scratch)";
    case B_INDIRECT_ARGS:
      return "IndirectArgs (scratch)";
    case B_NEIGHBOUR_LIST_1:
      return "NeighbourList (columns of block 1)";
    case B_NEIGHBOUR_LIST_2:
      return "NeighbourList (columns of block 2)";
    case B_NEIGHBOUR_LIST_3:
      return "NeighbourList (columns of block 3)";
    default:
      return "?";
  }
}

/// The storage-buffer bindings a SPIR-V module uses: the Binding decorations of the variables
/// that an instruction inside a function names (glslang declares every block of
/// kernel_common.glsl in every shader, and lists them all in the entry point's interface). A
/// literal that happens to equal a variable's id only adds a binding, which is harmless.
std::uint64_t spirv_bindings(const std::uint32_t* words, std::size_t count) {
  constexpr std::uint32_t kOpFunction = 54;
  constexpr std::uint32_t kOpFunctionEnd = 56;
  constexpr std::uint32_t kOpDecorate = 71;
  constexpr std::uint32_t kDecorationBinding = 33;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> binding_of;  // (variable id, binding)
  for (std::size_t at = 5; at < count;) {
    const std::uint32_t length = words[at] >> 16;
    if (length == 0 || at + length > count) break;
    if ((words[at] & 0xffffu) == kOpDecorate && length >= 4 &&
        words[at + 2] == kDecorationBinding) {
      binding_of.emplace_back(words[at + 1], words[at + 3]);
    }
    at += length;
  }
  std::uint64_t mask = 0;
  bool in_function = false;
  for (std::size_t at = 5; at < count;) {
    const std::uint32_t op = words[at] & 0xffffu;
    const std::uint32_t length = words[at] >> 16;
    if (length == 0 || at + length > count) break;
    if (op == kOpFunction) in_function = true;
    if (op == kOpFunctionEnd) in_function = false;
    for (std::size_t k = at + 1; in_function && k < at + length; ++k) {
      for (const auto& [id, binding] : binding_of) {
        if (words[k] == id && binding < 64) mask |= std::uint64_t{1} << binding;
      }
    }
    at += length;
  }
  return mask;
}

VkDeviceSize round_up(VkDeviceSize x, VkDeviceSize to) { return (x + to - 1) / to * to; }

/// The binding of the neighbour list's column block k.
std::uint32_t list_binding(std::uint32_t k) {
  return k == 0 ? std::uint32_t{B_NEIGHBOUR_LIST} : B_NEIGHBOUR_LIST_1 + (k - 1);
}

/// Bytes of the region a buffer's descriptor covers (never 0: Vulkan has no empty buffers).
VkDeviceSize padded(VkDeviceSize data_bytes) {
  return round_up(std::max<VkDeviceSize>(data_bytes, 4), 16);
}

}  // namespace

Status VulkanDevice::check(VkResult r, const char* what) {
  if (r == VK_SUCCESS) return Status::ok();
  std::string why = result_name(r);
  if (r == VK_ERROR_DEVICE_LOST) why += ": the GPU stopped responding (device lost)";
  if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY) why += ": out of GPU memory";
  Status s = Status::error(fmt::format("vulkan ({}): {} failed: {}", info_.name, what, why));
  if (error_.is_ok()) error_ = s;
  return s;
}

Result<std::unique_ptr<VulkanDevice>> VulkanDevice::create(std::shared_ptr<Instance> instance,
                                                           int physical) {
  std::unique_ptr<VulkanDevice> d(new VulkanDevice());
  if (Status s = d->init(std::move(instance), physical); !s) return s;
  return d;
}

Status VulkanDevice::init(std::shared_ptr<Instance> instance, int physical) {
  instance_ = std::move(instance);
  physical_ = instance_->devices()[static_cast<std::size_t>(physical)];
  info_ = physical_.info;
  if (physical_.compute_family == UINT32_MAX) {
    return Status::error(
        fmt::format("vulkan device {} ({}) has no compute queue", physical, info_.name));
  }
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue{};
  queue.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  queue.queueFamilyIndex = physical_.compute_family;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  // VK_EXT_memory_budget, where the device has it: what this process may still allocate on each
  // heap (available_bytes), rather than the heap's whole size.
  std::uint32_t extension_count = 0;
  vkEnumerateDeviceExtensionProperties(physical_.handle, nullptr, &extension_count, nullptr);
  std::vector<VkExtensionProperties> extensions(extension_count);
  vkEnumerateDeviceExtensionProperties(physical_.handle, nullptr, &extension_count,
                                       extensions.data());
  bool executable_properties = false;
  for (const VkExtensionProperties& e : extensions) {
    if (std::strcmp(e.extensionName, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME) == 0) {
      memory_budget_ = true;
    }
    if (std::strcmp(e.extensionName, VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME) == 0) {
      executable_properties = true;
    }
    if (std::strcmp(e.extensionName, VK_EXT_CONDITIONAL_RENDERING_EXTENSION_NAME) == 0) {
      conditional_ = true;
    }
  }
  // VK_EXT_conditional_rendering, where the device has it (MOTES_VULKAN_NO_CONDITIONAL=1: never,
  // so that tests cover the empty indirect dispatches too).
  VkPhysicalDeviceConditionalRenderingFeaturesEXT conditional{};
  conditional.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_CONDITIONAL_RENDERING_FEATURES_EXT;
  if (conditional_) {
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features.pNext = &conditional;
    vkGetPhysicalDeviceFeatures2(physical_.handle, &features);
    const char* off = std::getenv("MOTES_VULKAN_NO_CONDITIONAL");
    conditional_ = conditional.conditionalRendering == VK_TRUE &&
                   (off == nullptr || std::strcmp(off, "1") != 0);
  }
  std::vector<const char*> enabled;
  if (memory_budget_) enabled.push_back(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
  VkDeviceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue;
  if (conditional_) {
    enabled.push_back(VK_EXT_CONDITIONAL_RENDERING_EXTENSION_NAME);
    conditional = {};
    conditional.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_CONDITIONAL_RENDERING_FEATURES_EXT;
    conditional.conditionalRendering = VK_TRUE;
    info.pNext = &conditional;
  }
  shader_stats_ = ShaderStats::from_environment();
  VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR stats_feature{};
  shader_stats_.request(executable_properties, info_.name.c_str(), enabled, stats_feature,
                        info.pNext);
  info.enabledExtensionCount = static_cast<std::uint32_t>(enabled.size());
  info.ppEnabledExtensionNames = enabled.data();
  if (Status s =
          check(vkCreateDevice(physical_.handle, &info, nullptr, &device_), "vkCreateDevice");
      !s) {
    return s;
  }
  return init_queue(0);
}

Result<std::unique_ptr<VulkanDevice>> VulkanDevice::adopt(std::shared_ptr<Instance> instance,
                                                          int physical, VkDevice device,
                                                          std::uint32_t family, std::uint32_t index,
                                                          bool memory_budget) {
  std::unique_ptr<VulkanDevice> d(new VulkanDevice());
  d->instance_ = std::move(instance);
  d->physical_ = d->instance_->devices()[static_cast<std::size_t>(physical)];
  d->info_ = d->physical_.info;
  d->info_.detail += ", the program's device";
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(d->physical_.handle, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(d->physical_.handle, &count, families.data());
  d->physical_.compute_family = family;
  d->physical_.timestamp_bits = families.at(family).timestampValidBits;
  d->device_ = device;
  d->owns_device_ = false;
  d->begin_stages_ = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
  d->memory_budget_ = memory_budget;
  if (Status s = d->init_queue(index); !s) return s;
  return d;
}

Status VulkanDevice::init_queue(std::uint32_t queue_index) {
  volkLoadDevice(device_);
  if (const char* env = std::getenv("MOTES_VULKAN_MAX_GROUPS_X"); env != nullptr && *env != '\0') {
    const long v = std::strtol(env, nullptr, 10);
    if (v >= 1 && v < 65535) max_groups_x_ = static_cast<std::uint64_t>(v);
  }
  if (const char* env = std::getenv("MOTES_VULKAN_LIST_COLUMNS"); env != nullptr && *env != '\0') {
    const long v = std::strtol(env, nullptr, 10);
    if (v >= 1 && v < 65536) list_columns_cap_ = static_cast<std::uint32_t>(v);
  }
  if (const char* env = std::getenv("MOTES_VULKAN_CYCLES"); env != nullptr && *env != '\0') {
    const long v = std::strtol(env, nullptr, 10);
    if (v >= 1 && v <= 512) cycles_per_buffer_ = static_cast<std::size_t>(v);
  }
  small_rebuild_table_ = physical_.type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 0 : kSmallRebuildTable;
  if (const char* env = std::getenv("MOTES_VULKAN_SMALL_REBUILD"); env != nullptr && *env != '\0') {
    const long v = std::strtol(env, nullptr, 10);
    if (v >= 0 && v <= (1L << 31)) small_rebuild_table_ = static_cast<std::uint32_t>(v);
  }
  vkGetDeviceQueue(device_, physical_.compute_family, queue_index, &queue_);
  vkGetPhysicalDeviceMemoryProperties(physical_.handle, &memory_);

  VkCommandPoolCreateInfo pool{};
  pool.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool.queueFamilyIndex = physical_.compute_family;
  if (Status s = check(vkCreateCommandPool(device_, &pool, nullptr, &pool_), "vkCreateCommandPool");
      !s) {
    return s;
  }
  VkFenceCreateInfo fence{};
  fence.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  if (Status s = check(vkCreateFence(device_, &fence, nullptr, &fence_), "vkCreateFence"); !s) {
    return s;
  }
  return create_pipelines();
}

Status VulkanDevice::create_pipelines() {
  // The block scan and the one-workgroup rebuild's scan use subgroup arithmetic where the device
  // has it (MOTES_VULKAN_NO_SUBGROUPS=1 forces the shared-memory versions, so that tests cover
  // both).
  const char* no_subgroups = std::getenv("MOTES_VULKAN_NO_SUBGROUPS");
  use_subgroups_ = physical_.subgroup_arithmetic &&
                   (no_subgroups == nullptr || std::strcmp(no_subgroups, "1") != 0);
  std::uint32_t descriptors = 0;
  for (std::size_t i = 0; i < kPipelineCount; ++i) {
    std::string name = kPipelineShaders[i];
    if (use_subgroups_ && (static_cast<Pipeline>(i) == Pipeline::GridBuildScanBlock ||
                           static_cast<Pipeline>(i) == Pipeline::NeighboursUpdateSmall)) {
      name += "_subgroup";
    }
    shaders_[i] = find_shader(name);
    if (shaders_[i] == nullptr) {
      return Status::error(fmt::format("vulkan: shader {} is not embedded in this build", name));
    }
    used_bindings_[i] = spirv_bindings(shaders_[i]->words, shaders_[i]->word_count);
    descriptors += static_cast<std::uint32_t>(std::popcount(used_bindings_[i]));
  }

  // One descriptor set per pipeline holding only the buffers its shader uses: devices may allow
  // as few as 32 storage buffers per stage (lavapipe does), fewer than the backend has.
  VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, std::max(descriptors, 1u)};
  VkDescriptorPoolCreateInfo pool{};
  pool.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  pool.maxSets = static_cast<std::uint32_t>(kPipelineCount);
  pool.poolSizeCount = 1;
  pool.pPoolSizes = &pool_size;
  if (Status s = check(vkCreateDescriptorPool(device_, &pool, nullptr, &descriptor_pool_),
                       "vkCreateDescriptorPool");
      !s) {
    return s;
  }
  for (std::size_t i = 0; i < kPipelineCount; ++i) {
    std::vector<VkDescriptorSetLayoutBinding> bindings;
    for (std::uint32_t b = 0; b < kBindingCount; ++b) {
      if ((used_bindings_[i] >> b & 1u) == 0) continue;
      VkDescriptorSetLayoutBinding binding{};
      binding.binding = b;
      binding.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      binding.descriptorCount = 1;
      binding.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
      bindings.push_back(binding);
    }
    VkDescriptorSetLayoutCreateInfo set_info{};
    set_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    set_info.bindingCount = static_cast<std::uint32_t>(bindings.size());
    set_info.pBindings = bindings.data();
    if (Status s = check(vkCreateDescriptorSetLayout(device_, &set_info, nullptr, &set_layouts_[i]),
                         "vkCreateDescriptorSetLayout");
        !s) {
      return s;
    }
    VkPushConstantRange push{};
    push.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    push.size = sizeof(PushConstants);
    VkPipelineLayoutCreateInfo layout{};
    layout.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    layout.setLayoutCount = 1;
    layout.pSetLayouts = &set_layouts_[i];
    layout.pushConstantRangeCount = 1;
    layout.pPushConstantRanges = &push;
    if (Status s = check(vkCreatePipelineLayout(device_, &layout, nullptr, &pipeline_layouts_[i]),
                         "vkCreatePipelineLayout");
        !s) {
      return s;
    }
    VkDescriptorSetAllocateInfo alloc{};
    alloc.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    alloc.descriptorPool = descriptor_pool_;
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &set_layouts_[i];
    if (Status s =
            check(vkAllocateDescriptorSets(device_, &alloc, &sets_[i]), "vkAllocateDescriptorSets");
        !s) {
      return s;
    }
  }

  // A GPU compiles every pipeline now (tens of ms on an H200), so that no step pays for it: made
  // at its first use, an H200's W2 run of 2,000 steps took 4 ms longer (2 us a step) than before.
  // A CPU device (lavapipe: 0.3 to 0.4 s for them all, most of a conformance case's time) makes
  // each at its first use (pipeline_at).
  if (physical_.type != VK_PHYSICAL_DEVICE_TYPE_CPU) {
    for (std::size_t i = 0; i < kPipelineCount; ++i) {
      if (pipeline_at(i) == VK_NULL_HANDLE) return pipeline_error_;
    }
  }
  return Status::ok();
}

VkPipeline VulkanDevice::pipeline_at(std::size_t i) const {
  if (pipelines_[i] != VK_NULL_HANDLE || !pipeline_error_) return pipelines_[i];
  const Shader* shader = shaders_[i];
  VkShaderModuleCreateInfo module_info{};
  module_info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  module_info.codeSize = shader->word_count * 4;
  module_info.pCode = shader->words;
  VkShaderModule module = VK_NULL_HANDLE;
  VkResult r = vkCreateShaderModule(device_, &module_info, nullptr, &module);
  const char* what = "vkCreateShaderModule";
  if (r == VK_SUCCESS) {
    VkComputePipelineCreateInfo pipe{};
    pipe.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    pipe.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    pipe.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pipe.stage.module = module;
    pipe.stage.pName = "main";
    pipe.layout = pipeline_layouts_[i];
    // neighbours_update_small.glsl's workgroup size is specialization constant 0.
    const std::uint32_t small_threads = small_rebuild_threads();
    const VkSpecializationMapEntry entry{0, 0, sizeof(small_threads)};
    VkSpecializationInfo special{1, &entry, sizeof(small_threads), &small_threads};
    if (static_cast<Pipeline>(i) == Pipeline::NeighboursUpdateSmall) {
      pipe.stage.pSpecializationInfo = &special;
    }
    pipe.flags = shader_stats_.create_flags();
    r = vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &pipe, nullptr, &pipelines_[i]);
    if (r == VK_SUCCESS) shader_stats_.report(device_, pipelines_[i], shader->name);
    vkDestroyShaderModule(device_, module, nullptr);
    what = "vkCreateComputePipelines";
  }
  if (r != VK_SUCCESS) {
    pipelines_[i] = VK_NULL_HANDLE;
    pipeline_error_ = Status::error(fmt::format("vulkan ({}): {} of shader {} failed: {}",
                                                info_.name, what, shader->name, result_name(r)));
  }
  return pipelines_[i];
}

VulkanDevice::~VulkanDevice() {
  if (device_ != VK_NULL_HANDLE) {
    // Nothing of motes is in flight between calls (every submission is waited for); on a
    // program's device, waiting for it idle would also wait for (and race with) its own work.
    if (owns_device_) vkDeviceWaitIdle(device_);
    free_recordings();
    release_buffers();
    destroy_buffer(staging_);
    for (VkPipeline p : pipelines_) {
      if (p != VK_NULL_HANDLE) vkDestroyPipeline(device_, p, nullptr);
    }
    if (queries_ != VK_NULL_HANDLE) vkDestroyQueryPool(device_, queries_, nullptr);
    if (descriptor_pool_ != VK_NULL_HANDLE) {
      vkDestroyDescriptorPool(device_, descriptor_pool_, nullptr);
    }
    for (VkPipelineLayout l : pipeline_layouts_) {
      if (l != VK_NULL_HANDLE) vkDestroyPipelineLayout(device_, l, nullptr);
    }
    for (VkDescriptorSetLayout l : set_layouts_) {
      if (l != VK_NULL_HANDLE) vkDestroyDescriptorSetLayout(device_, l, nullptr);
    }
    if (fence_ != VK_NULL_HANDLE) vkDestroyFence(device_, fence_, nullptr);
    if (pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device_, pool_, nullptr);
    if (owns_device_) vkDestroyDevice(device_, nullptr);
  }
}

Status VulkanDevice::create_buffer(GpuBuffer& out, VkDeviceSize data_bytes, bool host_visible,
                                   const char* name) {
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = padded(data_bytes) + kGuardBytes;
  info.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  if (!host_visible) {
    // Vertex buffers too: a program drawing on the same device binds them (vulkan_interop.h).
    info.usage |= VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                  VK_BUFFER_USAGE_VERTEX_BUFFER_BIT;
    if (conditional_) info.usage |= VK_BUFFER_USAGE_CONDITIONAL_RENDERING_BIT_EXT;
  }
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  if (info.size > physical_.max_allocation && physical_.max_allocation != 0) {
    return Status::error(fmt::format(
        "vulkan ({}): buffer {} needs {} bytes, more than the device's largest allocation ({} "
        "bytes); use fewer particles",
        info_.name, name, info.size, physical_.max_allocation));
  }
  if (Status s = check(vkCreateBuffer(device_, &info, nullptr, &out.buffer), "vkCreateBuffer");
      !s) {
    return s;
  }
  out.data_bytes = data_bytes;
  VkMemoryRequirements req{};
  vkGetBufferMemoryRequirements(device_, out.buffer, &req);
  const VkMemoryPropertyFlags want =
      host_visible ? (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT |
                      VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
                   : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  const VkMemoryPropertyFlags need =
      host_visible ? (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)
                   : 0u;
  std::uint32_t type = UINT32_MAX;
  for (VkMemoryPropertyFlags flags : {want, need}) {
    for (std::uint32_t t = 0; t < memory_.memoryTypeCount && type == UINT32_MAX; ++t) {
      if ((req.memoryTypeBits & (1u << t)) != 0 &&
          (memory_.memoryTypes[t].propertyFlags & flags) == flags) {
        type = t;
      }
    }
  }
  if (type == UINT32_MAX) {
    return Status::error(
        fmt::format("vulkan ({}): no memory type for buffer {}", info_.name, name));
  }
  VkMemoryAllocateInfo alloc{};
  alloc.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = type;
  if (VkResult r = vkAllocateMemory(device_, &alloc, nullptr, &out.memory); r != VK_SUCCESS) {
    return Status::error(fmt::format(
        "vulkan ({}): cannot allocate {:.1f} MiB for buffer {}: {}{}", info_.name,
        static_cast<double>(req.size) / 1048576.0, name, result_name(r),
        r == VK_ERROR_OUT_OF_DEVICE_MEMORY ? " (out of GPU memory: use fewer particles)" : ""));
  }
  out.memory_bytes = req.size;
  if (Status s =
          check(vkBindBufferMemory(device_, out.buffer, out.memory, 0), "vkBindBufferMemory");
      !s) {
    return s;
  }
  if (host_visible) {
    if (Status s = check(vkMapMemory(device_, out.memory, 0, VK_WHOLE_SIZE, 0, &out.mapped),
                         "vkMapMemory");
        !s) {
      return s;
    }
  }
  return Status::ok();
}

void VulkanDevice::destroy_buffer(GpuBuffer& b) {
  if (b.buffer != VK_NULL_HANDLE) vkDestroyBuffer(device_, b.buffer, nullptr);
  if (b.memory != VK_NULL_HANDLE) vkFreeMemory(device_, b.memory, nullptr);
  b = GpuBuffer{};
}

void VulkanDevice::release_buffers() {
  for (GpuBuffer& b : buffers_) destroy_buffer(b);
  allocated_ = false;
}

Status VulkanDevice::ensure_staging(VkDeviceSize bytes) {
  if (staging_.buffer != VK_NULL_HANDLE && padded(staging_.data_bytes) >= bytes) {
    return Status::ok();
  }
  destroy_buffer(staging_);
  return create_buffer(staging_, std::max<VkDeviceSize>(bytes, VkDeviceSize{1} << 20), true,
                       "staging");
}

Status VulkanDevice::allocate(const Sizes& sizes) {
  if (sizes.table < 64 || (sizes.table & (sizes.table - 1)) != 0) {
    return Status::error(
        fmt::format("grid table size {} is not a power of two >= 64", sizes.table));
  }
  if (Status s = flush(); !s) return s;
  free_recordings();
  release_buffers();
  sizes_ = sizes;
  largest_body_ = 0;
  smallest_body_ = 0;

  // The bucket-count scan: level 0 is GridCellStart (T + 1 values); each level's block totals
  // are the next level's values, until one block holds them all.
  scan_levels_.clear();
  std::uint32_t count = sizes.table + 1;
  std::uint32_t offset = 0;
  bool in_scratch = false;
  std::uint32_t next = 0;
  while (true) {
    const std::uint32_t blocks = (count + SCAN_BLOCK - 1) / SCAN_BLOCK;
    scan_levels_.push_back({in_scratch ? 1u : 0u, offset, count, next});
    offset = next;
    next += blocks;
    if (blocks <= 1) break;
    count = blocks;
    in_scratch = true;
  }
  const std::uint32_t scratch_words = next;

  // The passes of a conditional rebuild, for the allocated sizes: their indirect arguments.
  shared::StepParams whole{};
  whole.particle_count = sizes.particles;
  whole.table_mask = sizes.table - 1;
  std::vector<Pass> rebuild = grid_build_passes(whole);
  for (const Pass& pass : neighbours_build_passes(whole)) rebuild.push_back(pass);
  rebuild_passes_ = static_cast<std::uint32_t>(rebuild.size());
  std::vector<std::uint32_t> rebuild_args;  // the template: (x, y, z, 0) per pass
  for (const Pass& pass : rebuild) {
    const std::array<std::uint32_t, 3> grid = group_grid(pass.groups);
    rebuild_args.insert(rebuild_args.end(), {grid[0], grid[1], grid[2], 0u});
  }

  list_columns_ = list_columns(sizes);
  for (std::uint32_t i = 0; i < kBindingCount; ++i) {
    VkDeviceSize bytes = 0;
    if (const int block = list_block(i); block >= 0) {
      bytes = list_block_bytes(sizes, list_columns_, static_cast<std::uint32_t>(block));
    } else if (i < kBufferCount) {
      bytes = buffer_layout(static_cast<Buffer>(i), sizes).bytes();
    } else if (i == B_SCAN_SCRATCH) {
      bytes = VkDeviceSize{scratch_words} * 4;
    } else if (i == B_INDIRECT_ARGS) {
      bytes = VkDeviceSize{rebuild_passes_} * 2 * 16 + 16;  // live, template, the gate word
    } else {
      bytes = VkDeviceSize{sizes.particles} * 4;
    }
    // The core refuses these sizes before it allocates (check_device_fits, buffer_limit); this
    // guards a direct caller of allocate().
    if (padded(bytes) > buffer_limit().bytes) {
      release_buffers();
      return Status::error(fmt::format(
          "vulkan ({}): buffer {} needs {} bytes, more than one buffer may hold on this device "
          "({} bytes, {}); use fewer particles",
          info_.name, binding_name(i), padded(bytes), buffer_limit().bytes, buffer_limit().what));
    }
    if (Status s = create_buffer(buffers_[i], bytes, false, binding_name(i)); !s) {
      release_buffers();
      return s;
    }
  }
  allocated_ = true;

  std::array<VkDescriptorBufferInfo, kBindingCount> infos{};
  for (std::uint32_t i = 0; i < kBindingCount; ++i) {
    infos[i] = {buffers_[i].buffer, 0, padded(buffers_[i].data_bytes)};
  }
  std::vector<VkWriteDescriptorSet> writes;
  for (std::size_t p = 0; p < kPipelineCount; ++p) {
    for (std::uint32_t i = 0; i < kBindingCount; ++i) {
      if ((used_bindings_[p] >> i & 1u) == 0) continue;
      VkWriteDescriptorSet w{};
      w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
      w.dstSet = sets_[p];
      w.dstBinding = i;
      w.descriptorCount = 1;
      w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      w.pBufferInfo = &infos[i];
      writes.push_back(w);
    }
  }
  vkUpdateDescriptorSets(device_, static_cast<std::uint32_t>(writes.size()), writes.data(), 0,
                         nullptr);

  // Zero every buffer and write the guard words after it; then the rebuild's template.
  const VkDeviceSize template_bytes = rebuild_args.size() * 4;
  if (Status s = ensure_staging(template_bytes); !s) return s;
  std::memcpy(staging_.mapped, rebuild_args.data(), template_bytes);
  return run_once([&](VkCommandBuffer cb) {
    for (const GpuBuffer& b : buffers_) {
      vkCmdFillBuffer(cb, b.buffer, 0, padded(b.data_bytes), 0);
      vkCmdFillBuffer(cb, b.buffer, padded(b.data_bytes), kGuardBytes, kGuardWord);
    }
    barrier(cb, Sync::All);
    const VkBufferCopy region{0, template_bytes, template_bytes};
    vkCmdCopyBuffer(cb, staging_.buffer, buffer(B_INDIRECT_ARGS), 1, &region);
  });
}

std::uint64_t VulkanDevice::required_bytes(const Sizes& sizes) const {
  // Every motes buffer, the grid build's scratch (2 N words, the scan's block sums), the rebuild's
  // indirect arguments, guard words and alignment.
  const std::uint64_t scan = (std::uint64_t{sizes.table} + 1) / (SCAN_BLOCK - 1) + 64;
  return buffers_bytes(sizes) + std::uint64_t{sizes.particles} * 8 + scan * 4 + 1024 +
         kBindingCount * (kGuardBytes + 16);
}

std::uint64_t VulkanDevice::available_bytes() const {
  // What allocate() gives back before it allocates again.
  std::uint64_t held = 0;
  for (const GpuBuffer& b : buffers_) held += b.memory_bytes;
  std::uint64_t best = 0;
  if (memory_budget_) {
    // VK_EXT_memory_budget: the heap's budget for this process less what it uses, on the
    // device-local heap with the most room.
    VkPhysicalDeviceMemoryBudgetPropertiesEXT budget{};
    budget.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT;
    VkPhysicalDeviceMemoryProperties2 props{};
    props.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2;
    props.pNext = &budget;
    vkGetPhysicalDeviceMemoryProperties2(physical_.handle, &props);
    for (std::uint32_t h = 0; h < props.memoryProperties.memoryHeapCount; ++h) {
      if ((props.memoryProperties.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) == 0) {
        continue;
      }
      const std::uint64_t used = budget.heapUsage[h];
      const std::uint64_t room = budget.heapBudget[h] > used ? budget.heapBudget[h] - used : 0;
      best = std::max(best, room + held);
    }
    if (best > 0) return best;
  }
  // Otherwise the largest device-local heap (the driver may keep a little of it for itself).
  for (std::uint32_t h = 0; h < memory_.memoryHeapCount; ++h) {
    if ((memory_.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) != 0) {
      best = std::max<std::uint64_t>(best, memory_.memoryHeaps[h].size);
    }
  }
  return best == 0 ? UINT64_MAX : best;
}

BufferSize VulkanDevice::largest_buffer(const Sizes& sizes) const {
  // The motes buffers and the grid build's scratch (GridArrival and GridUnsorted: N words; the
  // scan's block sums: fewer than T / (SCAN_BLOCK - 1) + 64 words), each padded as allocate()
  // pads it. The rebuild's indirect arguments are a few hundred bytes.
  BufferSize largest;
  const std::uint32_t columns = list_columns(sizes);
  for (std::uint32_t i = 0; i < kBindingCount; ++i) {
    std::uint64_t bytes = 0;
    if (const int block = list_block(i); block >= 0) {
      bytes = list_block_bytes(sizes, columns, static_cast<std::uint32_t>(block));
    } else if (i < kBufferCount) {
      bytes = buffer_layout(static_cast<Buffer>(i), sizes).bytes();
    } else if (i == B_SCAN_SCRATCH) {
      bytes = ((std::uint64_t{sizes.table} + 1) / (SCAN_BLOCK - 1) + 64) * 4;
    } else if (i == B_INDIRECT_ARGS) {
      continue;
    } else {
      bytes = std::uint64_t{sizes.particles} * 4;
    }
    bytes = padded(bytes);
    if (bytes > largest.bytes || largest.name.empty()) largest = {binding_name(i), bytes};
  }
  return largest;
}

BufferLimit VulkanDevice::buffer_limit() const {
  // A buffer is bound whole as one storage buffer, and is one allocation with its guard words.
  BufferLimit limit{physical_.max_storage_range, "maxStorageBufferRange"};
  if (physical_.max_allocation != 0 && physical_.max_allocation - kGuardBytes < limit.bytes) {
    limit = {physical_.max_allocation - kGuardBytes, "maxMemoryAllocationSize less guard words"};
  }
  return limit;
}

std::uint32_t VulkanDevice::list_columns(const Sizes& sizes) const {
  const std::uint32_t k = sizes.neighbour_capacity;
  const VkDeviceSize column = VkDeviceSize{sizes.particles} * 4;
  if (k == 0 || column == 0) return 0;
  const VkDeviceSize limit = buffer_limit().bytes;
  std::uint64_t fit = limit / column;  // columns one buffer holds, padded as allocate pads it
  while (fit > 0 && padded(fit * column) > limit) --fit;
  if (list_columns_cap_ != 0) fit = std::min<std::uint64_t>(fit, list_columns_cap_);
  if (fit >= k) return 0;  // one buffer holds the whole list
  // At most NEIGHBOUR_LIST_BLOCKS blocks: wider ones than fit are refused by allocate's check.
  const std::uint32_t fewest = (k + NEIGHBOUR_LIST_BLOCKS - 1) / NEIGHBOUR_LIST_BLOCKS;
  return std::max(static_cast<std::uint32_t>(fit), fewest);
}

int VulkanDevice::list_block(std::uint32_t binding) {
  if (binding == B_NEIGHBOUR_LIST) return 0;
  if (binding >= B_NEIGHBOUR_LIST_1 && binding <= B_NEIGHBOUR_LIST_3) {
    return static_cast<int>(binding - B_NEIGHBOUR_LIST_1) + 1;
  }
  return -1;
}

VkDeviceSize VulkanDevice::list_block_bytes(const Sizes& sizes, std::uint32_t columns,
                                            std::uint32_t block) {
  const std::uint32_t k = sizes.neighbour_capacity;
  const std::uint32_t width = columns == 0 ? k : columns;
  const std::uint64_t first = std::uint64_t{block} * width;
  if (first >= k) return 0;
  return std::min<std::uint64_t>(width, k - first) * VkDeviceSize{sizes.particles} * 4;
}

std::vector<VulkanDevice::Piece> VulkanDevice::pieces(Buffer b, VkDeviceSize offset,
                                                      VkDeviceSize bytes) const {
  std::vector<Piece> out;
  if (b != Buffer::NeighbourList) {
    out.push_back({static_cast<std::uint32_t>(b), offset, 0, bytes});
    return out;
  }
  // The column blocks are consecutive ranges of the whole list (entry k of particle i at k N + i).
  VkDeviceSize start = 0;
  for (std::uint32_t k = 0; k < NEIGHBOUR_LIST_BLOCKS; ++k) {
    const VkDeviceSize end = start + buffers_[list_binding(k)].data_bytes;
    const VkDeviceSize lo = std::max(offset, start);
    const VkDeviceSize hi = std::min(offset + bytes, end);
    if (lo < hi) out.push_back({list_binding(k), lo - start, lo - offset, hi - lo});
    start = end;
  }
  return out;
}

VkDeviceSize VulkanDevice::data_bytes(Buffer b) const {
  if (b != Buffer::NeighbourList) return buffers_[static_cast<std::size_t>(b)].data_bytes;
  VkDeviceSize sum = 0;
  for (std::uint32_t k = 0; k < NEIGHBOUR_LIST_BLOCKS; ++k) {
    sum += buffers_[list_binding(k)].data_bytes;
  }
  return sum;
}

Status VulkanDevice::write(Buffer b, const void* src, std::size_t bytes) {
  if (!allocated_) return Status::error("vulkan: write before allocate");
  if (bytes > data_bytes(b)) {
    return Status::error(fmt::format("vulkan: writing {} bytes into {} of {} bytes", bytes,
                                     buffer_name(b), data_bytes(b)));
  }
  if (b == Buffer::BodyFirst) {  // which impulses_apply shader suits the bodies
    largest_body_ = 0;
    smallest_body_ = 0;
    const std::size_t words = bytes / sizeof(shared::uint);
    if (words == std::size_t{sizes_.bodies} + 1 && words > 1) {
      std::vector<shared::uint> first(words);
      std::memcpy(first.data(), src, words * sizeof(shared::uint));
      smallest_body_ = ~shared::uint{0};
      for (std::size_t k = 0; k + 1 < words; ++k) {
        const shared::uint n = first[k + 1] > first[k] ? first[k + 1] - first[k] : 0u;
        largest_body_ = std::max(largest_body_, n);
        smallest_body_ = std::min(smallest_body_, n);
      }
    }
  }
  if (bytes == 0) return Status::ok();
  if (Status s = flush(); !s) return s;
  if (Status s = ensure_staging(bytes); !s) return s;
  std::memcpy(staging_.mapped, src, bytes);
  return run_once([&](VkCommandBuffer cb) {
    for (const Piece& piece : pieces(b, 0, bytes)) {
      const VkBufferCopy region{piece.at, piece.offset, piece.bytes};
      vkCmdCopyBuffer(cb, staging_.buffer, buffers_[piece.binding].buffer, 1, &region);
    }
  });
}

Status VulkanDevice::write_at(Buffer b, std::size_t offset, const void* src, std::size_t bytes) {
  // BodyFirst's whole contents choose the impulses_apply shader: the patched buffer goes through
  // write.
  if (b == Buffer::BodyFirst) return Device::write_at(b, offset, src, bytes);
  if (!allocated_) return Status::error("vulkan: write before allocate");
  if (offset > data_bytes(b) || bytes > data_bytes(b) - offset) {
    return Status::error(fmt::format("vulkan: writing {} bytes at {} into {} of {} bytes", bytes,
                                     offset, buffer_name(b), data_bytes(b)));
  }
  if (bytes == 0) return Status::ok();
  if (Status s = flush(); !s) return s;
  if (Status s = ensure_staging(bytes); !s) return s;
  std::memcpy(staging_.mapped, src, bytes);
  return run_once([&](VkCommandBuffer cb) {
    for (const Piece& piece : pieces(b, offset, bytes)) {
      const VkBufferCopy region{piece.at, piece.offset, piece.bytes};
      vkCmdCopyBuffer(cb, staging_.buffer, buffers_[piece.binding].buffer, 1, &region);
    }
  });
}

Status VulkanDevice::read(Buffer b, void* dst, std::size_t bytes) {
  if (!allocated_) return Status::error("vulkan: read before allocate");
  if (bytes > data_bytes(b)) {
    return Status::error(fmt::format("vulkan: reading {} bytes from {} of {} bytes", bytes,
                                     buffer_name(b), data_bytes(b)));
  }
  if (bytes == 0) return synchronize();
  if (Status s = flush(); !s) return s;
  if (Status s = ensure_staging(bytes); !s) return s;
  if (Status s = run_once([&](VkCommandBuffer cb) {
        for (const Piece& piece : pieces(b, 0, bytes)) {
          const VkBufferCopy region{piece.offset, piece.at, piece.bytes};
          vkCmdCopyBuffer(cb, buffers_[piece.binding].buffer, staging_.buffer, 1, &region);
        }
      });
      !s) {
    return s;
  }
  std::memcpy(dst, staging_.mapped, bytes);
  return validation_status();
}

Status VulkanDevice::synchronize() {
  if (Status s = flush(); !s) return s;
  return validation_status();
}

Status VulkanDevice::check_guards() {
  if (!allocated_) return Status::ok();
  if (Status s = flush(); !s) return s;
  if (Status s = ensure_staging(kGuardBytes * kBindingCount); !s) return s;
  if (Status s = run_once([&](VkCommandBuffer cb) {
        for (std::uint32_t i = 0; i < kBindingCount; ++i) {
          const VkBufferCopy region{padded(buffers_[i].data_bytes), i * kGuardBytes, kGuardBytes};
          vkCmdCopyBuffer(cb, buffers_[i].buffer, staging_.buffer, 1, &region);
        }
      });
      !s) {
    return s;
  }
  const auto* words = static_cast<const std::uint32_t*>(staging_.mapped);
  for (std::uint32_t i = 0; i < kBindingCount; ++i) {
    for (VkDeviceSize w = 0; w < kGuardBytes / 4; ++w) {
      if (words[i * kGuardBytes / 4 + w] != kGuardWord) {
        return Status::error(
            fmt::format("vulkan ({}): a kernel wrote past the end of {} ({} bytes)", info_.name,
                        binding_name(i), buffers_[i].data_bytes));
      }
    }
  }
  return validation_status();
}

Status VulkanDevice::validation_status() {
  if (!error_) return error_;
  MessageLog& log = instance_->log();
  const std::lock_guard<std::mutex> lock(log.mutex);
  if (log.messages.empty()) return Status::ok();
  std::string text =
      fmt::format("vulkan validation layer reported {} message{}:", log.messages.size(),
                  log.messages.size() == 1 ? "" : "s");
  for (const std::string& m : log.messages) text += "\n  " + m;
  log.messages.clear();
  return Status::error(text);
}

Listing list_devices() {
  Listing out;
  Result<std::shared_ptr<Instance>> inst = shared_instance();
  if (!inst) {
    out.reason = inst.message();
    return out;
  }
  for (const PhysicalDevice& d : inst.value()->devices()) out.devices.push_back(d.info);
  out.preferred = inst.value()->preferred();
  if (out.devices.empty()) out.reason = "the Vulkan loader found no device (no driver installed)";
  if (out.preferred >= 0) {
    out.preferred_is_gpu = inst.value()->devices()[static_cast<std::size_t>(out.preferred)].type !=
                           VK_PHYSICAL_DEVICE_TYPE_CPU;
  }
  return out;
}

Result<std::unique_ptr<Device>> open_device(int index) {
  Result<std::shared_ptr<Instance>> inst = shared_instance();
  if (!inst) return inst.status();
  const auto count = static_cast<int>(inst.value()->devices().size());
  if (index < 0) {
    if (const char* env = std::getenv("MOTES_VULKAN_DEVICE"); env != nullptr && *env != '\0') {
      char* end = nullptr;
      const long v = std::strtol(env, &end, 10);
      if (*end != '\0' || v < 0 || v >= count) {
        return Status::error(fmt::format(
            "MOTES_VULKAN_DEVICE='{}' is not a Vulkan device index (this machine has {})", env,
            count));
      }
      index = static_cast<int>(v);
    } else {
      index = inst.value()->preferred();
    }
  }
  if (count == 0) return Status::error("vulkan: the Vulkan loader found no device");
  if (index < 0 || index >= count) {
    return Status::error(
        fmt::format("vulkan device {} does not exist (this machine has {}; see `motes devices`)",
                    index, count));
  }
  Result<std::unique_ptr<VulkanDevice>> d = VulkanDevice::create(inst.value(), index);
  if (!d) return d.status();
  std::unique_ptr<Device> out = std::move(d.value());
  return out;
}

}  // namespace motes::vulkan
