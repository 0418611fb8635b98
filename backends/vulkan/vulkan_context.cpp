// Instance creation, validation messages and the description of every physical device.
#include "vulkan_context.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

namespace motes::vulkan {

const char* result_name(VkResult r) {
  switch (r) {
    case VK_SUCCESS:
      return "VK_SUCCESS";
    case VK_NOT_READY:
      return "VK_NOT_READY";
    case VK_TIMEOUT:
      return "VK_TIMEOUT";
    case VK_ERROR_OUT_OF_HOST_MEMORY:
      return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
      return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED:
      return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST:
      return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED:
      return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT:
      return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT:
      return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT:
      return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER:
      return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS:
      return "VK_ERROR_TOO_MANY_OBJECTS";
    default:
      return "VkResult error";
  }
}

bool validation_requested() {
  const char* v = std::getenv("MOTES_VULKAN_VALIDATION");
  return v != nullptr && *v != '\0' && std::strcmp(v, "0") != 0;
}

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data,
                                          void* user) {
  if (severity < VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) return VK_FALSE;
  auto* log = static_cast<MessageLog*>(user);
  const std::lock_guard<std::mutex> lock(log->mutex);
  if (log->messages.size() < 100) {
    log->messages.emplace_back(data->pMessage != nullptr ? data->pMessage : "(no text)");
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

const char* type_name(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "CPU";
    default:
      return "other";
  }
}

int type_rank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return 3;
    default:
      return 4;
  }
}

PhysicalDevice describe(VkPhysicalDevice handle, int index) {
  PhysicalDevice d;
  d.handle = handle;
  VkPhysicalDeviceSubgroupProperties subgroup{};
  subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
  VkPhysicalDeviceDriverProperties driver{};
  driver.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
  driver.pNext = &subgroup;
  VkPhysicalDeviceProperties2 props{};
  props.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
  props.pNext = &driver;
  vkGetPhysicalDeviceProperties2(handle, &props);
  const VkPhysicalDeviceProperties& p = props.properties;
  d.type = p.deviceType;
  // lavapipe runs constraints_relax's one workgroup 1.3 to 1.8 times slower than a dispatch per
  // colour (a 25 x 25 cloth, 2.4 against 3.1 to 4.5 ms a step): never in one launch there.
  if (d.type == VK_PHYSICAL_DEVICE_TYPE_CPU) d.info.one_launch_constraints = 0;
  d.subgroup_size = subgroup.subgroupSize;
  d.subgroup_arithmetic =
      (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0 &&
      (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT) != 0 &&
      (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_BASIC_BIT) != 0;
  d.max_workgroup_x =
      std::min(p.limits.maxComputeWorkGroupInvocations, p.limits.maxComputeWorkGroupSize[0]);
  d.max_storage_range = p.limits.maxStorageBufferRange;
  d.timestamp_period_ns = p.limits.timestampPeriod;

  VkPhysicalDeviceMaintenance3Properties m3{};
  m3.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES;
  VkPhysicalDeviceProperties2 props3{};
  props3.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
  props3.pNext = &m3;
  vkGetPhysicalDeviceProperties2(handle, &props3);
  d.max_allocation = m3.maxMemoryAllocationSize;

  std::uint32_t families = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(handle, &families, nullptr);
  std::vector<VkQueueFamilyProperties> fam(families);
  vkGetPhysicalDeviceQueueFamilyProperties(handle, &families, fam.data());
  for (std::uint32_t f = 0; f < families; ++f) {
    if ((fam[f].queueFlags & VK_QUEUE_COMPUTE_BIT) != 0) {
      d.compute_family = f;
      d.timestamp_bits = fam[f].timestampValidBits;
      break;
    }
  }

  VkPhysicalDeviceMemoryProperties mem{};
  vkGetPhysicalDeviceMemoryProperties(handle, &mem);
  std::uint64_t local = 0;
  for (std::uint32_t h = 0; h < mem.memoryHeapCount; ++h) {
    if ((mem.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) != 0) {
      local += mem.memoryHeaps[h].size;
    }
  }

  d.info.backend = "vulkan";
  d.info.index = index;
  d.info.name = p.deviceName;
  d.info.detail = fmt::format(
      "{}, driver {} {}, Vulkan {}.{}.{}, subgroup size {}{}, {:.1f} GiB device memory",
      type_name(d.type), driver.driverName, driver.driverInfo, VK_API_VERSION_MAJOR(p.apiVersion),
      VK_API_VERSION_MINOR(p.apiVersion), VK_API_VERSION_PATCH(p.apiVersion), d.subgroup_size,
      d.subgroup_arithmetic ? " with arithmetic" : "",
      static_cast<double>(local) / (1024.0 * 1024.0 * 1024.0));
  if (d.compute_family == UINT32_MAX) d.info.detail += ", no compute queue";
  return d;
}

}  // namespace

Result<std::unique_ptr<Instance>> Instance::create(bool validation) {
  if (VkResult r = volkInitialize(); r != VK_SUCCESS) {
    return Status::error(
        "no Vulkan loader (libvulkan.so.1 could not be loaded; Debian: libvulkan1 plus a driver "
        "such as mesa-vulkan-drivers)");
  }
  if (volkGetInstanceVersion() < VK_API_VERSION_1_2) {
    return Status::error("the Vulkan loader is older than Vulkan 1.2, which motes needs");
  }
  std::unique_ptr<Instance> inst(new Instance());

  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "motes";
  app.pEngineName = "motes";
  app.apiVersion = VK_API_VERSION_1_2;

  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  VkDebugUtilsMessengerCreateInfoEXT messenger{};
  messenger.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger.pfnUserCallback = on_message;
  messenger.pUserData = inst->log_.get();
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
  if (validation) {
    if (!layer_available(kValidationLayer)) {
      return Status::error(
          fmt::format("MOTES_VULKAN_VALIDATION is set but the layer {} is not installed (Debian: "
                      "vulkan-validationlayers)",
                      kValidationLayer));
    }
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    info.pNext = &features;
  }
  info.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  if (VkResult r = vkCreateInstance(&info, nullptr, &inst->instance_); r != VK_SUCCESS) {
    return Status::error(fmt::format(
        "cannot create a Vulkan instance: {}{}", result_name(r),
        r == VK_ERROR_INCOMPATIBLE_DRIVER ? " (no Vulkan 1.2 driver is installed)" : ""));
  }
  volkLoadInstanceOnly(inst->instance_);
  if (validation) {
    if (VkResult r =
            vkCreateDebugUtilsMessengerEXT(inst->instance_, &messenger, nullptr, &inst->messenger_);
        r != VK_SUCCESS) {
      return Status::error(
          fmt::format("cannot create the validation messenger: {}", result_name(r)));
    }
  }

  inst->describe_devices();
  return inst;
}

Result<std::unique_ptr<Instance>> Instance::adopt(VkInstance instance) {
  if (VkResult r = volkInitialize(); r != VK_SUCCESS) {
    return Status::error("no Vulkan loader (libvulkan.so.1 could not be loaded)");
  }
  std::unique_ptr<Instance> inst(new Instance());
  inst->instance_ = instance;
  inst->owned_ = false;
  // The instance-level functions are the loader's trampolines, the same for every instance, so
  // loading them from the program's instance leaves motes' own instance (if any) working.
  volkLoadInstanceOnly(instance);
  inst->describe_devices();
  return inst;
}

void Instance::describe_devices() {
  std::uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  std::vector<VkPhysicalDevice> handles(count);
  vkEnumeratePhysicalDevices(instance_, &count, handles.data());
  for (std::uint32_t i = 0; i < count; ++i) {
    devices_.push_back(describe(handles[i], static_cast<int>(i)));
  }
}

namespace {

std::mutex instance_mutex;

/// Heap-held so that no static destructor runs it: see release_shared_instance.
std::shared_ptr<Instance>& kept_instance() {
  static auto* kept = new std::shared_ptr<Instance>();
  return *kept;
}

/// Registered with atexit right after the instance is made, so it runs before the exit handlers
/// the driver registered while the instance was made (destroying an instance from a static
/// destructor, after NVIDIA's driver had cleaned up, crashed every program at exit).
void release_shared_instance() {
  const std::lock_guard<std::mutex> lock(instance_mutex);
  kept_instance().reset();
}

}  // namespace

Result<std::shared_ptr<Instance>> shared_instance() {
  const std::lock_guard<std::mutex> lock(instance_mutex);
  std::shared_ptr<Instance>& kept = kept_instance();
  if (kept) return kept;
  Result<std::unique_ptr<Instance>> made = Instance::create(validation_requested());
  if (!made) return made.status();
  kept = std::shared_ptr<Instance>(std::move(made.value()));
  std::atexit(release_shared_instance);
  return kept;
}

int Instance::preferred() const {
  int best = -1;
  for (std::size_t i = 0; i < devices_.size(); ++i) {
    if (devices_[i].compute_family == UINT32_MAX) continue;
    if (best < 0 ||
        type_rank(devices_[i].type) < type_rank(devices_[static_cast<std::size_t>(best)].type)) {
      best = static_cast<int>(i);
    }
  }
  return best;
}

Instance::~Instance() {
  if (!owned_) return;
  if (messenger_ != VK_NULL_HANDLE) vkDestroyDebugUtilsMessengerEXT(instance_, messenger_, nullptr);
  if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
}

}  // namespace motes::vulkan
