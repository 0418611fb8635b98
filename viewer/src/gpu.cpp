// The viewer's instance, device, queue and memory helpers.
#include "gpu.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "device_choice.h"

namespace motes::viewer {

const char* result_name(VkResult r) {
  switch (r) {
    case VK_SUCCESS:
      return "VK_SUCCESS";
    case VK_NOT_READY:
      return "VK_NOT_READY";
    case VK_TIMEOUT:
      return "VK_TIMEOUT";
    case VK_SUBOPTIMAL_KHR:
      return "VK_SUBOPTIMAL_KHR";
    case VK_ERROR_OUT_OF_DATE_KHR:
      return "VK_ERROR_OUT_OF_DATE_KHR";
    case VK_ERROR_SURFACE_LOST_KHR:
      return "VK_ERROR_SURFACE_LOST_KHR";
    case VK_ERROR_OUT_OF_HOST_MEMORY:
      return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
      return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED:
      return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST:
      return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT:
      return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT:
      return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT:
      return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER:
      return "VK_ERROR_INCOMPATIBLE_DRIVER";
    default:
      return "VkResult error";
  }
}

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) {
    throw std::runtime_error(fmt::format("viewer: {}: {}", what, result_name(r)));
  }
}

struct Messages {
  std::mutex mutex;
  std::vector<std::string> text;
};

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

bool validation_requested() {
  const char* v = std::getenv("MOTES_VULKAN_VALIDATION");
  return v != nullptr && *v != '\0' && std::strcmp(v, "0") != 0;
}

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data,
                                          void* user) {
  if (severity < VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) return VK_FALSE;
  auto* messages = static_cast<Messages*>(user);
  const std::lock_guard<std::mutex> lock(messages->mutex);
  if (messages->text.size() < 20) {
    messages->text.emplace_back(data->pMessage != nullptr ? data->pMessage : "(no text)");
  }
  return VK_FALSE;
}

bool layer_available(const char* name) {
  std::uint32_t count = 0;
  vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  return std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) {
    return std::strcmp(l.layerName, name) == 0;
  });
}

}  // namespace

Gpu::Gpu(const std::vector<const char*>& extensions) : messages_(std::make_unique<Messages>()) {
  if (volkInitialize() != VK_SUCCESS) {
    throw std::runtime_error(
        "viewer: no Vulkan loader (libvulkan.so.1; Debian: libvulkan1 plus a driver such as "
        "mesa-vulkan-drivers)");
  }
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "motes view";
  app.pEngineName = "motes";
  app.apiVersion = VK_API_VERSION_1_2;

  std::vector<const char*> exts = extensions;
  std::vector<const char*> layers;
  VkDebugUtilsMessengerCreateInfoEXT messenger{};
  messenger.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger.pfnUserCallback = on_message;
  messenger.pUserData = messages_.get();
  const VkValidationFeatureEnableEXT enables[] = {
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{};
  features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;
  features.pNext = &messenger;

  VkInstanceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  info.pApplicationInfo = &app;
  const bool validation = validation_requested();
  if (validation) {
    if (!layer_available(kValidationLayer)) {
      throw std::runtime_error(fmt::format(
          "viewer: MOTES_VULKAN_VALIDATION is set but the layer {} is not installed (Debian: "
          "vulkan-validationlayers)",
          kValidationLayer));
    }
    layers.push_back(kValidationLayer);
    exts.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    exts.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    info.pNext = &features;
  }
  info.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<std::uint32_t>(exts.size());
  info.ppEnabledExtensionNames = exts.data();
  check(vkCreateInstance(&info, nullptr, &instance), "cannot create a Vulkan instance");
  // Instance-level functions are the loader's trampolines, the same for every instance: loading
  // them from this one leaves the compute backend's instance working.
  volkLoadInstanceOnly(instance);
  if (validation) {
    check(vkCreateDebugUtilsMessengerEXT(instance, &messenger, nullptr, &messenger_),
          "cannot create the validation messenger");
  }
}

void Gpu::open(VkSurfaceKHR surface, int wanted) {
  std::uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance, &count, nullptr);
  std::vector<VkPhysicalDevice> handles(count);
  vkEnumeratePhysicalDevices(instance, &count, handles.data());
  // What each device offers (presenting asked of graphics families alone), then the choice
  // (device_choice.h).
  std::vector<DeviceFacts> facts(count);
  std::vector<std::string> names(count);
  for (std::uint32_t d = 0; d < count; ++d) {
    const VkPhysicalDevice h = handles[d];
    VkPhysicalDeviceProperties props{};
    vkGetPhysicalDeviceProperties(h, &props);
    facts[d].api_version = props.apiVersion;
    facts[d].type = props.deviceType;
    names[d] = props.deviceName;
    std::uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(h, &families, nullptr);
    facts[d].families.resize(families);
    vkGetPhysicalDeviceQueueFamilyProperties(h, &families, facts[d].families.data());
    facts[d].presents.assign(families, false);
    if (surface == VK_NULL_HANDLE || props.apiVersion < VK_API_VERSION_1_2) continue;
    for (std::uint32_t f = 0; f < families; ++f) {
      if ((facts[d].families[f].queueFlags & VK_QUEUE_GRAPHICS_BIT) == 0) continue;
      VkBool32 present = VK_FALSE;
      vkGetPhysicalDeviceSurfaceSupportKHR(h, f, surface, &present);
      facts[d].presents[f] = present == VK_TRUE;
    }
  }
  const DeviceChoice choice = choose_device(facts, surface != VK_NULL_HANDLE, wanted);
  if (choice.device < 0) throw std::runtime_error(choice.error);
  index = choice.device;
  physical = handles[static_cast<std::size_t>(index)];
  family = choice.family;
  family_computes = choice.family_computes;
  name = names[static_cast<std::size_t>(index)];
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo q{};
  q.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  q.queueFamilyIndex = family;
  q.queueCount = 1;
  q.pQueuePriorities = &priority;
  std::vector<const char*> exts;
  if (surface != VK_NULL_HANDLE) exts.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  // For motes' device on this one (handles()): how much memory is left, where the driver says.
  std::uint32_t ext_count = 0;
  vkEnumerateDeviceExtensionProperties(physical, nullptr, &ext_count, nullptr);
  std::vector<VkExtensionProperties> available(ext_count);
  vkEnumerateDeviceExtensionProperties(physical, nullptr, &ext_count, available.data());
  for (const VkExtensionProperties& e : available) {
    if (std::strcmp(e.extensionName, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME) == 0) {
      memory_budget = true;
      exts.push_back(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
    }
    // For a CUDA run's particles copied into the viewer's memory (cuda_share.h).
    if (std::strcmp(e.extensionName, VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME) == 0) {
      external_memory_fd = true;
      exts.push_back(VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
    }
  }
  VkPhysicalDeviceIDProperties id{};
  id.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES;
  VkPhysicalDeviceProperties2 props2{};
  props2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
  props2.pNext = &id;
  vkGetPhysicalDeviceProperties2(physical, &props2);
  std::memcpy(uuid.data(), id.deviceUUID, uuid.size());
  VkDeviceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &q;
  info.enabledExtensionCount = static_cast<std::uint32_t>(exts.size());
  info.ppEnabledExtensionNames = exts.data();
  check(vkCreateDevice(physical, &info, nullptr, &device), "cannot create the drawing device");
  volkLoadDeviceTable(&vk, device);
  vk.vkGetDeviceQueue(device, family, 0, &queue);
  VkCommandPoolCreateInfo pool_info{};
  pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = family;
  check(vk.vkCreateCommandPool(device, &pool_info, nullptr, &pool), "vkCreateCommandPool");
  VkFenceCreateInfo fence_info{};
  fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  check(vk.vkCreateFence(device, &fence_info, nullptr, &fence), "vkCreateFence");
}

motes::VulkanHandles Gpu::handles() const {
  motes::VulkanHandles h;
  h.instance = instance;
  h.physical_device = physical;
  h.device = device;
  h.queue_family = family;
  h.queue_index = 0;
  h.memory_budget = memory_budget;
  return h;
}

Result<std::unique_ptr<Device>> open_compute_device(const Gpu& gpu) {
  if (!gpu.family_computes) {
    return Status::error(fmt::format("the drawing queue of {} cannot compute", gpu.name));
  }
  return open_vulkan_device(gpu.handles());
}

void Gpu::check_messages() const {
  const std::lock_guard<std::mutex> lock(messages_->mutex);
  if (messages_->text.empty()) return;
  std::string all = "viewer: Vulkan validation:";
  for (const std::string& m : messages_->text) all += "\n  " + m;
  messages_->text.clear();
  throw std::runtime_error(all);
}

VkCommandBuffer Gpu::begin_commands() const {
  VkCommandBufferAllocateInfo alloc{};
  alloc.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  alloc.commandPool = pool;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  check(vk.vkAllocateCommandBuffers(device, &alloc, &cmd), "vkAllocateCommandBuffers");
  VkCommandBufferBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vk.vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
  return cmd;
}

void Gpu::submit_and_wait(VkCommandBuffer cmd) const {
  check(vk.vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  VkSubmitInfo submit{};
  submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  check(vk.vkQueueSubmit(queue, 1, &submit, fence), "vkQueueSubmit");
  check(vk.vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  check(vk.vkResetFences(device, 1, &fence), "vkResetFences");
  vk.vkFreeCommandBuffers(device, pool, 1, &cmd);
  check_messages();
}

std::uint32_t Gpu::memory_type(std::uint32_t bits, VkMemoryPropertyFlags flags) const {
  VkPhysicalDeviceMemoryProperties mem{};
  vkGetPhysicalDeviceMemoryProperties(physical, &mem);
  for (std::uint32_t i = 0; i < mem.memoryTypeCount; ++i) {
    if ((bits & (1u << i)) != 0 && (mem.memoryTypes[i].propertyFlags & flags) == flags) return i;
  }
  throw std::runtime_error("viewer: no suitable Vulkan memory type");
}

VkDeviceMemory Gpu::allocate(const VkMemoryRequirements& req, VkMemoryPropertyFlags flags,
                             const void* next) const {
  VkMemoryAllocateInfo alloc{};
  alloc.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  alloc.pNext = next;
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = memory_type(req.memoryTypeBits, flags);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  check(vk.vkAllocateMemory(device, &alloc, nullptr, &memory), "vkAllocateMemory");
  return memory;
}

Gpu::~Gpu() {
  if (device != VK_NULL_HANDLE) {
    vk.vkDeviceWaitIdle(device);
    if (fence != VK_NULL_HANDLE) vk.vkDestroyFence(device, fence, nullptr);
    if (pool != VK_NULL_HANDLE) vk.vkDestroyCommandPool(device, pool, nullptr);
    vk.vkDestroyDevice(device, nullptr);
  }
  if (messenger_ != VK_NULL_HANDLE) vkDestroyDebugUtilsMessengerEXT(instance, messenger_, nullptr);
  if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
}

HostBuffer::HostBuffer(const Gpu& g, VkDeviceSize bytes, VkBufferUsageFlags usage)
    : gpu(g), size(bytes) {
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = bytes;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(gpu.vk.vkCreateBuffer(gpu.device, &info, nullptr, &buffer), "vkCreateBuffer");
  VkMemoryRequirements req{};
  gpu.vk.vkGetBufferMemoryRequirements(gpu.device, buffer, &req);
  memory =
      gpu.allocate(req, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  check(gpu.vk.vkBindBufferMemory(gpu.device, buffer, memory, 0), "vkBindBufferMemory");
  check(gpu.vk.vkMapMemory(gpu.device, memory, 0, VK_WHOLE_SIZE, 0, &mapped), "vkMapMemory");
}

HostBuffer::~HostBuffer() {
  if (memory != VK_NULL_HANDLE) gpu.vk.vkFreeMemory(gpu.device, memory, nullptr);
  if (buffer != VK_NULL_HANDLE) gpu.vk.vkDestroyBuffer(gpu.device, buffer, nullptr);
}

DeviceBuffer::DeviceBuffer(const Gpu& g, const void* data, VkDeviceSize size,
                           VkBufferUsageFlags usage)
    : gpu(g) {
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = size;
  info.usage = usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(gpu.vk.vkCreateBuffer(gpu.device, &info, nullptr, &buffer), "vkCreateBuffer");
  VkMemoryRequirements req{};
  gpu.vk.vkGetBufferMemoryRequirements(gpu.device, buffer, &req);
  memory = gpu.allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  check(gpu.vk.vkBindBufferMemory(gpu.device, buffer, memory, 0), "vkBindBufferMemory");
  const HostBuffer staging(gpu, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  std::memcpy(staging.mapped, data, size);
  VkCommandBuffer cmd = gpu.begin_commands();
  const VkBufferCopy region{0, 0, size};
  gpu.vk.vkCmdCopyBuffer(cmd, staging.buffer, buffer, 1, &region);
  VkMemoryBarrier to_vertices{};
  to_vertices.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  to_vertices.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  to_vertices.dstAccessMask = VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT;
  gpu.vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                              VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, 0, 1, &to_vertices, 0, nullptr, 0,
                              nullptr);
  gpu.submit_and_wait(cmd);
}

DeviceBuffer::~DeviceBuffer() {
  if (buffer != VK_NULL_HANDLE) gpu.vk.vkDestroyBuffer(gpu.device, buffer, nullptr);
  if (memory != VK_NULL_HANDLE) gpu.vk.vkFreeMemory(gpu.device, memory, nullptr);
}

DeviceImage::DeviceImage(const Gpu& g, VkFormat format, VkExtent2D extent, VkImageUsageFlags usage,
                         VkImageAspectFlags aspect)
    : gpu(g) {
  VkImageCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {extent.width, extent.height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  check(gpu.vk.vkCreateImage(gpu.device, &info, nullptr, &image), "vkCreateImage");
  VkMemoryRequirements req{};
  gpu.vk.vkGetImageMemoryRequirements(gpu.device, image, &req);
  memory = gpu.allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  check(gpu.vk.vkBindImageMemory(gpu.device, image, memory, 0), "vkBindImageMemory");
  VkImageViewCreateInfo view_info{};
  view_info.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  view_info.image = image;
  view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
  view_info.format = format;
  view_info.subresourceRange = {aspect, 0, 1, 0, 1};
  check(gpu.vk.vkCreateImageView(gpu.device, &view_info, nullptr, &view), "vkCreateImageView");
}

DeviceImage::~DeviceImage() {
  if (view != VK_NULL_HANDLE) gpu.vk.vkDestroyImageView(gpu.device, view, nullptr);
  if (image != VK_NULL_HANDLE) gpu.vk.vkDestroyImage(gpu.device, image, nullptr);
  if (memory != VK_NULL_HANDLE) gpu.vk.vkFreeMemory(gpu.device, memory, nullptr);
}

}  // namespace motes::viewer
