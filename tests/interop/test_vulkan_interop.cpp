// motes on a program's own Vulkan device (motes/vulkan_interop.h): the handles it refuses and
// why, and a program that reads motes' particle buffers itself after every step, on lavapipe (or
// any device) under the Khronos validation layer with synchronization validation when it is
// installed, which must say nothing; without the barrier the header asks for, it must.
#include <gtest/gtest.h>
#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstring>
#include <mutex>
#include <numeric>
#include <string>
#include <vector>

#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "motes/vulkan_interop.h"
#include "queue_family.h"

namespace {

// A box, a free sphere and a rope: the device orders their particles box, sphere, rope; the
// scene sphere, box, rope.
constexpr const char* kScene = R"({
  "settings": { "dt": 5e-5, "gravity": [0.0, -9.81, 0.0], "particle_diameter": 0.01,
                "contact": { "stiffness": 500, "damping": 50, "tangential": 20, "friction": 0.5 } },
  "materials": { "wood": { "density": 700.0 } },
  "planes": [ { "name": "floor", "normal": [0, 1, 0], "point": [0, 0, 0] } ],
  "bodies": [
    { "name": "ball", "material": "wood", "shape": { "type": "particle" },
      "position": [0.1, 0.05, 0.0] },
    { "name": "box", "material": "wood", "shape": { "type": "box", "particles": [3, 3, 3] },
      "position": [0.0, 0.03, 0.0] },
    { "name": "rope", "kind": "rope", "material": "wood",
      "rope": { "from": [-0.1, 0.1, 0.0], "to": [-0.02, 0.1, 0.0], "particles": 9, "pin": [0] } }
  ]
})";

motes::Scene scene() { return motes::load_scene_text(kScene, "interop scene", ".").value(); }

/// The program's side: its own instance (validation and synchronization validation when the
/// layer is installed, its messages collected), the first device with a queue family that draws
/// and computes, that family's queue, a command pool and a host-visible buffer to copy into.
struct Program {
  static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                   void* user) {
    if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
      auto* self = static_cast<Program*>(user);
      const std::lock_guard<std::mutex> lock(self->mutex);
      self->messages.emplace_back(data->pMessage != nullptr ? data->pMessage : "");
    }
    return VK_FALSE;
  }

  Program() {
    std::uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    validated = std::any_of(layers.begin(), layers.end(), [](const VkLayerProperties& l) {
      return std::strcmp(l.layerName, "VK_LAYER_KHRONOS_validation") == 0;
    });
    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.apiVersion = VK_API_VERSION_1_2;
    VkDebugUtilsMessengerCreateInfoEXT messenger_info{};
    messenger_info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    messenger_info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                                     VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messenger_info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                                 VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
    messenger_info.pfnUserCallback = on_message;
    messenger_info.pUserData = this;
    const VkValidationFeatureEnableEXT sync =
        VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT features{};
    features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    features.pNext = &messenger_info;
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = &sync;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const char* exts[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME,
                          VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
    VkInstanceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    info.pApplicationInfo = &app;
    if (validated) {
      info.pNext = &features;
      info.enabledLayerCount = 1;
      info.ppEnabledLayerNames = &layer;
      info.enabledExtensionCount = 2;
      info.ppEnabledExtensionNames = exts;
    }
    if (vkCreateInstance(&info, nullptr, &instance) != VK_SUCCESS) return;
    if (validated) {
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
      create(instance, &messenger_info, nullptr, &messenger);
    }
    vkEnumeratePhysicalDevices(instance, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(instance, &count, devices.data());
    for (VkPhysicalDevice d : devices) {
      std::uint32_t n = 0;
      vkGetPhysicalDeviceQueueFamilyProperties(d, &n, nullptr);
      std::vector<VkQueueFamilyProperties> families(n);
      vkGetPhysicalDeviceQueueFamilyProperties(d, &n, families.data());
      for (std::uint32_t f = 0; f < n && physical == VK_NULL_HANDLE; ++f) {
        const VkQueueFlags both = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
        if ((families[f].queueFlags & both) == both) {
          physical = d;
          family = f;
          family_queues = families[f].queueCount;
        }
      }
    }
    if (physical == VK_NULL_HANDLE) return;
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{};
    queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queue_info.queueFamilyIndex = family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    VkDeviceCreateInfo device_info{};
    device_info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    if (vkCreateDevice(physical, &device_info, nullptr, &device) != VK_SUCCESS) return;
    vkGetDeviceQueue(device, family, 0, &queue);
    VkCommandPoolCreateInfo pool_info{};
    pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pool_info.queueFamilyIndex = family;
    vkCreateCommandPool(device, &pool_info, nullptr, &pool);
    VkFenceCreateInfo fence_info{};
    fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    vkCreateFence(device, &fence_info, nullptr, &fence);
  }

  ~Program() {
    if (device != VK_NULL_HANDLE) {
      vkDeviceWaitIdle(device);
      if (copy_memory != VK_NULL_HANDLE) vkFreeMemory(device, copy_memory, nullptr);
      if (copy != VK_NULL_HANDLE) vkDestroyBuffer(device, copy, nullptr);
      vkDestroyFence(device, fence, nullptr);
      vkDestroyCommandPool(device, pool, nullptr);
      vkDestroyDevice(device, nullptr);
    }
    if (messenger != VK_NULL_HANDLE) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      destroy(instance, messenger, nullptr);
    }
    if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
  }
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  [[nodiscard]] bool ready() const { return fence != VK_NULL_HANDLE; }

  [[nodiscard]] motes::VulkanHandles handles() const {
    motes::VulkanHandles h;
    h.instance = instance;
    h.physical_device = physical;
    h.device = device;
    h.queue_family = family;
    return h;
  }

  /// The validation messages so far, emptied.
  std::vector<std::string> take_messages() {
    const std::lock_guard<std::mutex> lock(mutex);
    std::vector<std::string> out;
    out.swap(messages);
    return out;
  }

  VkCommandBuffer begin() {
    VkCommandBufferAllocateInfo alloc{};
    alloc.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    alloc.commandPool = pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    vkAllocateCommandBuffers(device, &alloc, &cmd);
    VkCommandBufferBeginInfo info{};
    info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    vkBeginCommandBuffer(cmd, &info);
    return cmd;
  }

  /// Submits `cmd`; with `wait`, waits for it and for everything submitted before.
  void submit(VkCommandBuffer cmd, bool wait = true) {
    vkEndCommandBuffer(cmd);
    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd;
    vkQueueSubmit(queue, 1, &submit, wait ? fence : VK_NULL_HANDLE);
    submitted.push_back(cmd);
    if (!wait) return;
    vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX);
    vkResetFences(device, 1, &fence);
    vkFreeCommandBuffers(device, pool, static_cast<std::uint32_t>(submitted.size()),
                         submitted.data());
    submitted.clear();
  }

  /// Copies `range` into host memory on the program's queue, after the barrier the header asks
  /// for unless `barrier` is false, and returns it.
  std::vector<float> read(const motes::VulkanBufferRange& range, bool barrier) {
    if (copy == VK_NULL_HANDLE) {
      VkBufferCreateInfo info{};
      info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
      info.size = range.size;
      info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
      vkCreateBuffer(device, &info, nullptr, &copy);
      VkMemoryRequirements req{};
      vkGetBufferMemoryRequirements(device, copy, &req);
      VkPhysicalDeviceMemoryProperties mem{};
      vkGetPhysicalDeviceMemoryProperties(physical, &mem);
      const VkMemoryPropertyFlags want =
          VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
      VkMemoryAllocateInfo alloc{};
      alloc.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
      alloc.allocationSize = req.size;
      for (std::uint32_t t = 0; t < mem.memoryTypeCount; ++t) {
        if ((req.memoryTypeBits >> t & 1u) != 0 &&
            (mem.memoryTypes[t].propertyFlags & want) == want) {
          alloc.memoryTypeIndex = t;
          break;
        }
      }
      vkAllocateMemory(device, &alloc, nullptr, &copy_memory);
      vkBindBufferMemory(device, copy, copy_memory, 0);
    }
    VkCommandBuffer cmd = begin();
    record_read(cmd, range, barrier);
    submit(cmd);
    std::vector<float> out(range.size / sizeof(float));
    void* mapped = nullptr;
    vkMapMemory(device, copy_memory, 0, range.size, 0, &mapped);
    std::memcpy(out.data(), mapped, range.size);
    vkUnmapMemory(device, copy_memory);
    return out;
  }

  /// The copy of read(), recorded into `cmd`.
  void record_read(VkCommandBuffer cmd, const motes::VulkanBufferRange& range, bool barrier) {
    if (barrier) {
      const VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr, motes::kVulkanWriteAccess,
                              VK_ACCESS_TRANSFER_READ_BIT};
      vkCmdPipelineBarrier(cmd, motes::kVulkanWriteStages, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &b,
                           0, nullptr, 0, nullptr);
    }
    const VkBufferCopy region{range.offset, 0, range.size};
    vkCmdCopyBuffer(cmd, range.buffer, copy, 1, &region);
    const VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr,
                                  VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_HOST_READ_BIT};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                         &to_host, 0, nullptr, 0, nullptr);
  }

  /// Writes zeros over `range` and copies it out in one command buffer, with the barrier the
  /// header asks for between unless `barrier` is false.
  void write_then_read(const motes::VulkanBufferRange& range, bool barrier) {
    read(range, true);  // makes the program's buffer
    VkCommandBuffer cmd = begin();
    vkCmdFillBuffer(cmd, range.buffer, range.offset, range.size, 0);
    record_read(cmd, range, barrier);
    submit(cmd);
  }

  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::uint32_t family = 0;
  std::uint32_t family_queues = 0;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkBuffer copy = VK_NULL_HANDLE;
  VkDeviceMemory copy_memory = VK_NULL_HANDLE;
  std::vector<VkCommandBuffer> submitted;  ///< not yet waited for
  bool validated = false;
  std::mutex mutex;
  std::vector<std::string> messages;
};

/// `result` failed with a message that contains `part`.
template <class R>
void expect_error(const R& result, const std::string& part) {
  ASSERT_FALSE(result) << "expected an error containing: " << part;
  EXPECT_NE(result.message().find(part), std::string::npos) << result.message();
}

TEST(VulkanInterop, RefusesNullHandles) {
  Program p;
  if (!p.ready()) GTEST_SKIP() << "skipped: no Vulkan device that draws and computes";
  motes::VulkanHandles h = p.handles();
  h.instance = VK_NULL_HANDLE;
  expect_error(motes::open_vulkan_device(h), "VulkanHandles::instance is VK_NULL_HANDLE");
  h = p.handles();
  h.physical_device = VK_NULL_HANDLE;
  expect_error(motes::open_vulkan_device(h), "VulkanHandles::physical_device is VK_NULL_HANDLE");
  h = p.handles();
  h.device = VK_NULL_HANDLE;
  expect_error(motes::open_vulkan_device(h), "VulkanHandles::device is VK_NULL_HANDLE");
}

TEST(VulkanInterop, RefusesAPhysicalDeviceOfAnotherInstance) {
  Program p, other;
  if (!p.ready() || !other.ready()) GTEST_SKIP() << "skipped: no Vulkan device";
  motes::VulkanHandles h = p.handles();
  h.physical_device = other.physical;
  expect_error(motes::open_vulkan_device(h), "not one of the instance's");
}

TEST(VulkanInterop, RefusesQueuesThatDoNotExistOrCannotCompute) {
  Program p;
  if (!p.ready()) GTEST_SKIP() << "skipped: no Vulkan device";
  motes::VulkanHandles h = p.handles();
  h.queue_family = 99;
  expect_error(motes::open_vulkan_device(h), "queue family 99 does not exist");
  h = p.handles();
  h.queue_index = p.family_queues;
  expect_error(motes::open_vulkan_device(h),
               "queue " + std::to_string(p.family_queues) + " of family");
  // A family without compute, which this machine's devices may lack: the rule alone.
  const VkQueueFamilyProperties families[2] = {{VK_QUEUE_TRANSFER_BIT, 2, 0, {1, 1, 1}},
                                               {VK_QUEUE_COMPUTE_BIT, 1, 0, {1, 1, 1}}};
  EXPECT_NE(motes::vulkan::queue_family_error(families, 0, 0).find("queue family 0 has no compute"),
            std::string::npos);
  EXPECT_EQ(motes::vulkan::queue_family_error(families, 1, 0), "");
  EXPECT_NE(motes::vulkan::queue_family_error(families, 1, 1).find("the family has 1"),
            std::string::npos);
}

TEST(VulkanInterop, ParticleBuffersOnlyOfASimulationOnTheProgramsDevice) {
  auto on_openmp = motes::Simulation::create(scene(), motes::open_device("openmp").value()).value();
  expect_error(motes::vulkan_particle_buffers(*on_openmp), "runs on openmp");
  motes::Result<std::unique_ptr<motes::Device>> own = motes::open_device("vulkan");
  if (!own) GTEST_SKIP() << "skipped: no Vulkan device for motes";
  auto on_own = motes::Simulation::create(scene(), std::move(own).value()).value();
  expect_error(motes::vulkan_particle_buffers(*on_own), "motes' own Vulkan device");
}

TEST(VulkanInterop, AProgramReadsTheParticlesAfterEveryStep) {
  Program p;
  if (!p.ready()) GTEST_SKIP() << "skipped: no Vulkan device";
  std::printf("validation layer with synchronization validation: %s\n",
              p.validated ? "on" : "not installed");
  auto device = motes::open_vulkan_device(p.handles());
  ASSERT_TRUE(device) << device.message();
  auto sim = motes::Simulation::create(scene(), std::move(device).value()).value();
  const std::vector<std::uint32_t> order = sim->scene_particle_order();
  ASSERT_EQ(order.size(), sim->particle_count());
  std::vector<std::uint32_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::uint32_t> all(order.size());
  std::iota(all.begin(), all.end(), 0u);
  EXPECT_EQ(sorted, all);  // a permutation
  EXPECT_NE(order, all);   // and not the identity, for this scene
  for (int frame = 0; frame < 5; ++frame) {
    ASSERT_TRUE(sim->step(20));
    const auto buffers = motes::vulkan_particle_buffers(*sim);
    ASSERT_TRUE(buffers) << buffers.message();
    EXPECT_EQ(buffers->positions.count, sim->particle_count());
    EXPECT_EQ(buffers->positions.stride, 16u);
    EXPECT_EQ(buffers->positions.size, 16u * sim->particle_count());
    const std::vector<float> pos = p.read(buffers->positions, true);
    const std::vector<float> vel = p.read(buffers->velocities, true);
    const motes::Snapshot s = sim->snapshot().value();
    for (std::size_t i = 0; i < order.size(); ++i) {
      const motes::shared::vec4& q = s.particle_pos[order[i]];
      const motes::shared::vec4& v = s.particle_vel[order[i]];
      ASSERT_EQ(pos[4 * i + 1], q.y) << "device particle " << i;
      ASSERT_EQ(pos[4 * i + 3], q.w);
      ASSERT_EQ(vel[4 * i + 1], v.y);
    }
  }
  const std::vector<std::string> messages = p.take_messages();
  EXPECT_TRUE(messages.empty()) << messages.front();
}

// The test above passes in silence only if the layer watches: it must see a read of a buffer
// just written with nothing between, and nothing with the header's barrier there. (Debian 12's
// layer, 1.3.239, checks hazards within a command buffer; those between motes' submissions and
// the program's, which the barrier is for, it does not see.)
TEST(VulkanInterop, SynchronizationValidationSeesAReadWithoutTheBarrier) {
  Program p;
  if (!p.ready()) GTEST_SKIP() << "skipped: no Vulkan device";
  if (!p.validated)
    GTEST_SKIP() << "skipped: no validation layer (Debian: vulkan-validationlayers)";
  auto sim =
      motes::Simulation::create(scene(), motes::open_vulkan_device(p.handles()).value()).value();
  const auto buffers = motes::vulkan_particle_buffers(*sim).value();
  p.write_then_read(buffers.velocities, true);
  std::vector<std::string> messages = p.take_messages();
  EXPECT_TRUE(messages.empty()) << messages.front();
  p.write_then_read(buffers.velocities, false);
  messages = p.take_messages();
  ASSERT_FALSE(messages.empty()) << "the layer said nothing about a read after a write";
  EXPECT_NE(messages.front().find("SYNC-HAZARD-READ-AFTER-WRITE"), std::string::npos)
      << messages.front();
}

}  // namespace
