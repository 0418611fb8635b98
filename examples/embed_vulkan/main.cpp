// A program that owns its Vulkan instance, device and queue, runs a motes simulation on them and
// draws the particles itself, reading motes' position and velocity buffers as vertex buffers (no
// copy), into an offscreen picture written as a PPM file; it prints how many pixels are not the
// background. Usage: motes_embed_vulkan SCENE.json OUT.ppm [FRAMES]
// (scripts/check-package.sh runs it under the validation layer through the loader's environment:
// VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation and VK_LAYER_ENABLES=...SYNCHRONIZATION...)
#include <vulkan/vulkan.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "motes/scene.h"
#include "motes/simulation.h"
#include "motes/vulkan_interop.h"
#include "points_frag.h"
#include "points_vert.h"

namespace {

constexpr std::uint32_t kWidth = 640, kHeight = 480;

void check(VkResult r, const char* what) {
  if (r == VK_SUCCESS) return;
  std::fprintf(stderr, "motes_embed_vulkan: %s failed (%d)\n", what, static_cast<int>(r));
  std::exit(1);
}

int fail(const std::string& message) {
  std::fprintf(stderr, "motes_embed_vulkan: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return fail("usage: motes_embed_vulkan SCENE.json OUT.ppm [FRAMES]");
  const int frames = argc > 3 ? std::atoi(argv[3]) : 10;

  // The program's Vulkan: instance, the first device, a queue family that draws and computes
  // (every Vulkan GPU has one), dynamic rendering and points larger than a pixel.
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo instance_info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, nullptr, 0, &app};
  VkInstance instance;
  check(vkCreateInstance(&instance_info, nullptr, &instance), "vkCreateInstance");
  std::uint32_t n = 1;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  vkEnumeratePhysicalDevices(instance, &n, &physical);
  if (physical == VK_NULL_HANDLE) return fail("no Vulkan device");
  std::vector<VkQueueFamilyProperties> families(16);
  n = 16;
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &n, families.data());
  const VkQueueFlags both = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
  std::uint32_t family = 0;
  while (family + 1 < n && (families[family].queueFlags & both) != both) ++family;
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{
      VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO, nullptr, 0, family, 1, &priority};
  VkPhysicalDeviceVulkan13Features v13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  v13.dynamicRendering = VK_TRUE;
  VkPhysicalDeviceFeatures features{};
  features.largePoints = VK_TRUE;
  VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &v13, 0, 1, &queue_info};
  device_info.pEnabledFeatures = &features;
  VkDevice device;
  check(vkCreateDevice(physical, &device_info, nullptr, &device), "vkCreateDevice");
  VkQueue queue;
  vkGetDeviceQueue(device, family, 0, &queue);

  // motes on that device and queue.
  motes::Result<motes::Scene> scene = motes::load_scene_file(argv[1]);
  if (!scene) return fail(scene.message());
  auto motes_device = motes::open_vulkan_device({instance, physical, device, family, 0, false});
  if (!motes_device) return fail(motes_device.message());
  auto made = motes::Simulation::create(scene.value(), std::move(motes_device).value());
  if (!made) return fail(made.message());
  std::unique_ptr<motes::Simulation> sim = std::move(made).value();
  auto particles = motes::vulkan_particle_buffers(*sim);
  if (!particles) return fail(particles.message());
  // The view: the first frame's extent in x and y, with a margin (a snapshot, once).
  float lo[2] = {1e30f, 1e30f}, hi[2] = {-1e30f, -1e30f};
  for (const motes::shared::vec4& p : sim->snapshot().value().particle_pos) {
    lo[0] = std::min(lo[0], p.x), hi[0] = std::max(hi[0], p.x);
    lo[1] = std::min(lo[1], p.y), hi[1] = std::max(hi[1], p.y);
  }
  const float scale = 0.8f * std::min(kWidth / (hi[0] - lo[0] + 1e-3f),  // pixels a metre
                                      kHeight / (hi[1] - lo[1] + 1e-3f));
  const float view[6] = {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, scale, 0.0f, kWidth, kHeight};

  // A colour image to draw into, and host memory to read it back into.
  VkPhysicalDeviceMemoryProperties memory;
  vkGetPhysicalDeviceMemoryProperties(physical, &memory);
  auto allocate = [&](VkMemoryRequirements req, VkMemoryPropertyFlags flags) {
    std::uint32_t t = 0;
    while (!(req.memoryTypeBits >> t & 1u) ||
           (memory.memoryTypes[t].propertyFlags & flags) != flags)
      ++t;
    VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, nullptr, req.size, t};
    VkDeviceMemory m;
    check(vkAllocateMemory(device, &info, nullptr, &m), "vkAllocateMemory");
    return m;
  };
  const VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  const VkImageSubresourceRange whole{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkImageCreateInfo image_info{
      VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO,
      nullptr,
      0,
      VK_IMAGE_TYPE_2D,
      format,
      {kWidth, kHeight, 1},
      1,
      1,
      VK_SAMPLE_COUNT_1_BIT,
      VK_IMAGE_TILING_OPTIMAL,
      VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT};
  VkImage image;
  check(vkCreateImage(device, &image_info, nullptr, &image), "vkCreateImage");
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device, image, &req);
  VkDeviceMemory image_memory = allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  vkBindImageMemory(device, image, image_memory, 0);
  VkImageViewCreateInfo view_info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO,
                                  nullptr,
                                  0,
                                  image,
                                  VK_IMAGE_VIEW_TYPE_2D,
                                  format,
                                  {},
                                  whole};
  VkImageView image_view;
  check(vkCreateImageView(device, &view_info, nullptr, &image_view), "vkCreateImageView");
  VkBufferCreateInfo readback_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, nullptr, 0,
                                   4 * kWidth * kHeight, VK_BUFFER_USAGE_TRANSFER_DST_BIT};
  VkBuffer readback;
  check(vkCreateBuffer(device, &readback_info, nullptr, &readback), "vkCreateBuffer");
  vkGetBufferMemoryRequirements(device, readback, &req);
  VkDeviceMemory readback_memory = allocate(req, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
  vkBindBufferMemory(device, readback, readback_memory, 0);

  // The pipeline: points from two per-vertex vec4 buffers, motes' layout as it is.
  auto module = [&](const std::uint32_t* code, std::size_t bytes) {
    VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO, nullptr, 0, bytes,
                                  code};
    VkShaderModule m;
    check(vkCreateShaderModule(device, &info, nullptr, &m), "vkCreateShaderModule");
    return m;
  };
  VkPipelineShaderStageCreateInfo stages[2] = {
      {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_VERTEX_BIT,
       module(points_vert, sizeof(points_vert)), "main"},
      {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0,
       VK_SHADER_STAGE_FRAGMENT_BIT, module(points_frag, sizeof(points_frag)), "main"}};
  const VkVertexInputBindingDescription bindings[2] = {{0, 16, VK_VERTEX_INPUT_RATE_VERTEX},
                                                       {1, 16, VK_VERTEX_INPUT_RATE_VERTEX}};
  const VkVertexInputAttributeDescription attributes[2] = {
      {0, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 0}, {1, 1, VK_FORMAT_R32G32B32A32_SFLOAT, 0}};
  VkPipelineVertexInputStateCreateInfo input{
      VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
      nullptr,
      0,
      2,
      bindings,
      2,
      attributes};
  VkPipelineInputAssemblyStateCreateInfo assembly{
      VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO, nullptr, 0,
      VK_PRIMITIVE_TOPOLOGY_POINT_LIST};
  const VkViewport viewport{0, 0, kWidth, kHeight, 0, 1};
  const VkRect2D area{{0, 0}, {kWidth, kHeight}};
  VkPipelineViewportStateCreateInfo viewports{
      VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO, nullptr, 0, 1, &viewport, 1, &area};
  VkPipelineRasterizationStateCreateInfo raster{
      VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo multisample{
      VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO, nullptr, 0, VK_SAMPLE_COUNT_1_BIT};
  VkPipelineColorBlendAttachmentState blend{};
  blend.colorWriteMask = 0xf;
  VkPipelineColorBlendStateCreateInfo blending{
      VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
      nullptr,
      0,
      VK_FALSE,
      VK_LOGIC_OP_CLEAR,
      1,
      &blend};
  const VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(view)};
  VkPipelineLayoutCreateInfo layout_info{
      VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, nullptr, 0, 0, nullptr, 1, &push};
  VkPipelineLayout layout;
  check(vkCreatePipelineLayout(device, &layout_info, nullptr, &layout), "vkCreatePipelineLayout");
  VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO, nullptr,
                                          0, 1, &format};
  VkGraphicsPipelineCreateInfo pipeline_info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO,
                                             &rendering,
                                             0,
                                             2,
                                             stages,
                                             &input,
                                             &assembly,
                                             nullptr,
                                             &viewports,
                                             &raster,
                                             &multisample,
                                             nullptr,
                                             &blending,
                                             nullptr,
                                             layout};
  VkPipeline pipeline;
  check(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &pipeline_info, nullptr, &pipeline),
        "vkCreateGraphicsPipelines");

  // One command buffer, recorded once, submitted after each frame's steps: the barrier motes asks
  // for (motes/vulkan_interop.h) with the image's change to drawing, the points, the read-back.
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO, nullptr, 0, family};
  VkCommandPool pool;
  check(vkCreateCommandPool(device, &pool_info, nullptr, &pool), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr, pool,
                                    VK_COMMAND_BUFFER_LEVEL_PRIMARY, 1};
  VkCommandBuffer cmd;
  check(vkAllocateCommandBuffers(device, &alloc, &cmd), "vkAllocateCommandBuffers");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkBeginCommandBuffer(cmd, &begin);
  const VkMemoryBarrier after_motes{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr,
                                    motes::kVulkanWriteAccess, VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT};
  VkImageMemoryBarrier to_draw{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER,
                               nullptr,
                               VK_ACCESS_TRANSFER_READ_BIT,
                               VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                               VK_IMAGE_LAYOUT_UNDEFINED,
                               VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                               VK_QUEUE_FAMILY_IGNORED,
                               VK_QUEUE_FAMILY_IGNORED,
                               image,
                               whole};
  vkCmdPipelineBarrier(
      cmd, motes::kVulkanWriteStages,
      VK_PIPELINE_STAGE_VERTEX_INPUT_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, 0, 1,
      &after_motes, 0, nullptr, 1, &to_draw);
  VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO, nullptr, image_view,
                                  VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  color.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  color.clearValue.color = {{0.95f, 0.95f, 0.95f, 1.0f}};  // 242 in 8 bits
  VkRenderingInfo rendering_info{
      VK_STRUCTURE_TYPE_RENDERING_INFO, nullptr, 0, area, 1, 0, 1, &color};
  vkCmdBeginRendering(cmd, &rendering_info);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
  vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(view), view);
  const VkBuffer buffers[2] = {particles->positions.buffer, particles->velocities.buffer};
  const VkDeviceSize offsets[2] = {particles->positions.offset, particles->velocities.offset};
  vkCmdBindVertexBuffers(cmd, 0, 2, buffers, offsets);
  vkCmdDraw(cmd, particles->positions.count, 1, 0, 0);
  vkCmdEndRendering(cmd);
  VkImageMemoryBarrier to_copy = to_draw;
  to_copy.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  to_copy.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  to_copy.oldLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  to_copy.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &to_copy);
  const VkBufferImageCopy region{
      0, 0, 0, {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {}, {kWidth, kHeight, 1}};
  vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback, 1, &region);
  const VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr,
                                VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_HOST_READ_BIT};
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                       &to_host, 0, nullptr, 0, nullptr);
  check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");

  // Step, draw, step, draw on the one queue. No wait between: motes' submissions wait on the
  // device for what came before them on the queue, and each of its calls waits for its own work.
  const auto steps = static_cast<std::uint64_t>(
      std::max(1.0, std::round(1.0 / (60.0 * scene->settings.dt))));  // 1/60 s a frame
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence;
  check(vkCreateFence(device, &fence_info, nullptr, &fence), "vkCreateFence");
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO, nullptr, 0, nullptr, nullptr, 1, &cmd};
  for (int frame = 0; frame < frames; ++frame) {
    if (motes::Status s = sim->step(steps); !s) return fail(s.message());
    check(vkQueueSubmit(queue, 1, &submit, frame + 1 == frames ? fence : VK_NULL_HANDLE),
          "vkQueueSubmit");
  }
  check(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");

  // The picture as a PPM file, and how many pixels are not the background.
  void* mapped;
  vkMapMemory(device, readback_memory, 0, VK_WHOLE_SIZE, 0, &mapped);
  const auto* rgba = static_cast<const unsigned char*>(mapped);
  std::ofstream out(argv[2], std::ios::binary);
  out << "P6\n" << kWidth << " " << kHeight << "\n255\n";
  std::size_t drawn = 0;
  for (std::size_t i = 0; i < std::size_t{kWidth} * kHeight; ++i) {
    out.write(reinterpret_cast<const char*>(rgba + 4 * i), 3);
    drawn += rgba[4 * i] != 242 || rgba[4 * i + 1] != 242 || rgba[4 * i + 2] != 242;
  }
  vkUnmapMemory(device, readback_memory);
  std::printf("%u particles after %d frames: %zu of %u pixels drawn; picture %s\n",
              particles->positions.count, frames, drawn, kWidth * kHeight, argv[2]);

  sim.reset();  // motes' objects on the device go before it
  vkDestroyFence(device, fence, nullptr);
  vkDestroyCommandPool(device, pool, nullptr);
  vkDestroyPipeline(device, pipeline, nullptr);
  vkDestroyPipelineLayout(device, layout, nullptr);
  for (const VkPipelineShaderStageCreateInfo& s : stages) {
    vkDestroyShaderModule(device, s.module, nullptr);
  }
  vkDestroyBuffer(device, readback, nullptr);
  vkFreeMemory(device, readback_memory, nullptr);
  vkDestroyImageView(device, image_view, nullptr);
  vkDestroyImage(device, image, nullptr);
  vkFreeMemory(device, image_memory, nullptr);
  vkDestroyDevice(device, nullptr);
  vkDestroyInstance(instance, nullptr);
  return 0;
}
