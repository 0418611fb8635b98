// A program that owns its Vulkan instance, device and queue, runs a motes simulation on them and
// draws the particles itself, reading motes' position and velocity buffers as vertex buffers (no
// copy), into an offscreen picture written as a PPM file; it prints how many pixels are not the
// background. Vulkan through Vulkan-Hpp's RAII classes (Debian: libvulkan-dev). Usage:
//   motes_embed_vulkan SCENE.json OUT.ppm [FRAMES]
// (scripts/check-package.sh runs it under the validation layer through the loader's environment:
// VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation and VK_LAYER_ENABLES=...SYNCHRONIZATION...)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vulkan/vulkan_raii.hpp>

#include "motes/scene.h"
#include "motes/simulation.h"
#include "motes/vulkan_interop.h"
#include "points_frag.h"
#include "points_vert.h"

namespace {

constexpr std::uint32_t kWidth = 640, kHeight = 480;

int fail(const std::string& message) {
  std::fprintf(stderr, "motes_embed_vulkan: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 3) return fail("usage: motes_embed_vulkan SCENE.json OUT.ppm [FRAMES]");
  const int frames = argc > 3 ? std::atoi(argv[3]) : 10;

  // The program's Vulkan: instance, the first device, a queue family that draws and computes
  // (every Vulkan GPU has one), dynamic rendering and points larger than a pixel.
  vk::raii::Context context;
  const vk::ApplicationInfo app(nullptr, 0, nullptr, 0, VK_API_VERSION_1_3);
  vk::raii::Instance instance(context, vk::InstanceCreateInfo({}, &app));
  vk::raii::PhysicalDevice physical = std::move(vk::raii::PhysicalDevices(instance).front());
  const std::vector<vk::QueueFamilyProperties> families = physical.getQueueFamilyProperties();
  const vk::QueueFlags both = vk::QueueFlagBits::eGraphics | vk::QueueFlagBits::eCompute;
  std::uint32_t family = 0;
  while (family + 1 < families.size() && (families[family].queueFlags & both) != both) ++family;
  const float priority = 1.0f;
  const vk::DeviceQueueCreateInfo queue_info({}, family, 1, &priority);
  vk::PhysicalDeviceFeatures features;
  features.largePoints = VK_TRUE;
  const vk::StructureChain<vk::DeviceCreateInfo, vk::PhysicalDeviceVulkan13Features> device_info(
      vk::DeviceCreateInfo({}, queue_info, {}, {}, &features),
      vk::PhysicalDeviceVulkan13Features().setDynamicRendering(VK_TRUE));
  vk::raii::Device device(physical, device_info.get<vk::DeviceCreateInfo>());
  vk::raii::Queue queue(device, family, 0);

  // A colour image to draw into, and host memory to read it back into.
  const vk::PhysicalDeviceMemoryProperties memory = physical.getMemoryProperties();
  auto allocate = [&](vk::MemoryRequirements req, vk::MemoryPropertyFlags flags) {
    std::uint32_t t = 0;
    while (!(req.memoryTypeBits >> t & 1u) ||
           (memory.memoryTypes[t].propertyFlags & flags) != flags)
      ++t;
    return vk::raii::DeviceMemory(device, vk::MemoryAllocateInfo(req.size, t));
  };
  const vk::Format format = vk::Format::eR8G8B8A8Unorm;
  const vk::ImageSubresourceRange whole(vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1);
  vk::raii::Image image(
      device, vk::ImageCreateInfo(
                  {}, vk::ImageType::e2D, format, {kWidth, kHeight, 1}, 1, 1,
                  vk::SampleCountFlagBits::e1, vk::ImageTiling::eOptimal,
                  vk::ImageUsageFlagBits::eColorAttachment | vk::ImageUsageFlagBits::eTransferSrc));
  vk::raii::DeviceMemory image_memory =
      allocate(image.getMemoryRequirements(), vk::MemoryPropertyFlagBits::eDeviceLocal);
  image.bindMemory(*image_memory, 0);
  vk::raii::ImageView image_view(
      device, vk::ImageViewCreateInfo({}, *image, vk::ImageViewType::e2D, format, {}, whole));
  vk::raii::Buffer readback(device, vk::BufferCreateInfo({}, 4 * kWidth * kHeight,
                                                         vk::BufferUsageFlagBits::eTransferDst));
  vk::raii::DeviceMemory readback_memory =
      allocate(readback.getMemoryRequirements(), vk::MemoryPropertyFlagBits::eHostVisible |
                                                     vk::MemoryPropertyFlagBits::eHostCoherent);
  readback.bindMemory(*readback_memory, 0);

  // motes on that device and queue; destroyed before it (declared after it).
  motes::Result<motes::Scene> scene = motes::load_scene_file(argv[1]);
  if (!scene) return fail(scene.message());
  auto motes_device = motes::open_vulkan_device({static_cast<VkInstance>(*instance),
                                                 static_cast<VkPhysicalDevice>(*physical),
                                                 static_cast<VkDevice>(*device), family, 0, false});
  if (!motes_device) return fail(motes_device.message());
  auto made = motes::Simulation::create(scene.value(), std::move(motes_device).value());
  if (!made) return fail(made.message());
  std::unique_ptr<motes::Simulation> sim = std::move(made).value();
  auto particles = motes::vulkan_particle_buffers(*sim);
  if (!particles) return fail(particles.message());
  // The view: the first frame's extent in x and y, with a margin (a snapshot, once).
  float lo[2] = {1e30f, 1e30f}, hi[2] = {-1e30f, -1e30f};
  motes::Result<motes::Snapshot> first = sim->snapshot();
  if (!first) return fail(first.message());
  for (const motes::shared::vec4& p : first->particle_pos) {
    lo[0] = std::min(lo[0], p.x), hi[0] = std::max(hi[0], p.x);
    lo[1] = std::min(lo[1], p.y), hi[1] = std::max(hi[1], p.y);
  }
  const float scale = 0.8f * std::min(kWidth / (hi[0] - lo[0] + 1e-3f),  // pixels a metre
                                      kHeight / (hi[1] - lo[1] + 1e-3f));
  const std::array<float, 6> view = {
      (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, scale, 0.0f, kWidth, kHeight};

  // The pipeline: points from two per-vertex vec4 buffers, motes' layout as it is.
  vk::raii::ShaderModule vert(device,
                              vk::ShaderModuleCreateInfo({}, sizeof(points_vert), points_vert));
  vk::raii::ShaderModule frag(device,
                              vk::ShaderModuleCreateInfo({}, sizeof(points_frag), points_frag));
  const std::array<vk::PipelineShaderStageCreateInfo, 2> stages = {
      vk::PipelineShaderStageCreateInfo({}, vk::ShaderStageFlagBits::eVertex, *vert, "main"),
      vk::PipelineShaderStageCreateInfo({}, vk::ShaderStageFlagBits::eFragment, *frag, "main")};
  const std::array<vk::VertexInputBindingDescription, 2> bindings = {
      vk::VertexInputBindingDescription(0, 16), vk::VertexInputBindingDescription(1, 16)};
  const std::array<vk::VertexInputAttributeDescription, 2> attributes = {
      vk::VertexInputAttributeDescription(0, 0, vk::Format::eR32G32B32A32Sfloat, 0),
      vk::VertexInputAttributeDescription(1, 1, vk::Format::eR32G32B32A32Sfloat, 0)};
  const vk::PipelineVertexInputStateCreateInfo input({}, bindings, attributes);
  const vk::PipelineInputAssemblyStateCreateInfo assembly({}, vk::PrimitiveTopology::ePointList);
  const vk::Viewport viewport(0, 0, kWidth, kHeight, 0, 1);
  const vk::Rect2D area({0, 0}, {kWidth, kHeight});
  const vk::PipelineViewportStateCreateInfo viewports({}, viewport, area);
  vk::PipelineRasterizationStateCreateInfo raster;
  raster.lineWidth = 1.0f;
  const vk::PipelineMultisampleStateCreateInfo multisample;
  vk::PipelineColorBlendAttachmentState blend;
  blend.colorWriteMask = vk::FlagTraits<vk::ColorComponentFlagBits>::allFlags;
  const vk::PipelineColorBlendStateCreateInfo blending({}, VK_FALSE, vk::LogicOp::eClear, blend);
  const vk::PushConstantRange push(vk::ShaderStageFlagBits::eVertex, 0, sizeof(view));
  vk::raii::PipelineLayout layout(device, vk::PipelineLayoutCreateInfo({}, {}, push));
  const vk::StructureChain<vk::GraphicsPipelineCreateInfo, vk::PipelineRenderingCreateInfo> info(
      vk::GraphicsPipelineCreateInfo({}, stages, &input, &assembly, nullptr, &viewports, &raster,
                                     &multisample, nullptr, &blending, nullptr, *layout),
      vk::PipelineRenderingCreateInfo(0, format));
  vk::raii::Pipeline pipeline(device, nullptr, info.get<vk::GraphicsPipelineCreateInfo>());

  // One command buffer, recorded once, submitted after each frame's steps: the barrier motes asks
  // for (motes/vulkan_interop.h) with the image's change to drawing, the points, the read-back.
  vk::raii::CommandPool pool(device, vk::CommandPoolCreateInfo({}, family));
  vk::raii::CommandBuffer cmd = std::move(vk::raii::CommandBuffers(
      device, vk::CommandBufferAllocateInfo(*pool, vk::CommandBufferLevel::ePrimary, 1))[0]);
  cmd.begin({});
  const vk::MemoryBarrier after_motes(vk::AccessFlags(motes::kVulkanWriteAccess),
                                      vk::AccessFlagBits::eVertexAttributeRead);
  const vk::ImageMemoryBarrier to_draw(
      vk::AccessFlagBits::eTransferRead, vk::AccessFlagBits::eColorAttachmentWrite,
      vk::ImageLayout::eUndefined, vk::ImageLayout::eColorAttachmentOptimal,
      VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, *image, whole);
  cmd.pipelineBarrier(
      vk::PipelineStageFlags(motes::kVulkanWriteStages),
      vk::PipelineStageFlagBits::eVertexInput | vk::PipelineStageFlagBits::eColorAttachmentOutput,
      {}, after_motes, {}, to_draw);
  const vk::RenderingAttachmentInfo color(
      *image_view, vk::ImageLayout::eColorAttachmentOptimal, {}, {}, {},
      vk::AttachmentLoadOp::eClear, vk::AttachmentStoreOp::eStore,
      vk::ClearColorValue(std::array<float, 4>{0.95f, 0.95f, 0.95f, 1.0f}));  // 242 in 8 bits
  cmd.beginRendering(vk::RenderingInfo({}, area, 1, 0, color));
  cmd.bindPipeline(vk::PipelineBindPoint::eGraphics, *pipeline);
  cmd.pushConstants<float>(*layout, vk::ShaderStageFlagBits::eVertex, 0, view);
  cmd.bindVertexBuffers(0, {particles->positions.buffer, particles->velocities.buffer},
                        {particles->positions.offset, particles->velocities.offset});
  cmd.draw(particles->positions.count, 1, 0, 0);
  cmd.endRendering();
  const vk::ImageMemoryBarrier to_copy(
      vk::AccessFlagBits::eColorAttachmentWrite, vk::AccessFlagBits::eTransferRead,
      vk::ImageLayout::eColorAttachmentOptimal, vk::ImageLayout::eTransferSrcOptimal,
      VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, *image, whole);
  cmd.pipelineBarrier(vk::PipelineStageFlagBits::eColorAttachmentOutput,
                      vk::PipelineStageFlagBits::eTransfer, {}, {}, {}, to_copy);
  cmd.copyImageToBuffer(*image, vk::ImageLayout::eTransferSrcOptimal, *readback,
                        vk::BufferImageCopy(0, 0, 0, {vk::ImageAspectFlagBits::eColor, 0, 0, 1}, {},
                                            {kWidth, kHeight, 1}));
  cmd.pipelineBarrier(
      vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eHost, {},
      vk::MemoryBarrier(vk::AccessFlagBits::eTransferWrite, vk::AccessFlagBits::eHostRead), {}, {});
  cmd.end();

  // Step, draw, step, draw on the one queue. No wait between: motes' submissions wait on the
  // device for what came before them on the queue, and each of its calls waits for its own work.
  const auto steps = static_cast<std::uint64_t>(
      std::max(1.0, std::round(1.0 / (60.0 * scene->settings.dt))));  // 1/60 s a frame
  vk::raii::Fence fence(device, vk::FenceCreateInfo());
  const vk::SubmitInfo submit({}, {}, *cmd);
  for (int frame = 0; frame < frames; ++frame) {
    if (motes::Status s = sim->step(steps); !s) return fail(s.message());
    queue.submit(submit, frame + 1 == frames ? *fence : vk::Fence{});
  }
  if (device.waitForFences(*fence, VK_TRUE, UINT64_MAX) != vk::Result::eSuccess) return 1;

  // The picture as a PPM file, and how many pixels are not the background.
  const auto* rgba = static_cast<const unsigned char*>(readback_memory.mapMemory(0, VK_WHOLE_SIZE));
  std::ofstream out(argv[2], std::ios::binary);
  out << "P6\n" << kWidth << " " << kHeight << "\n255\n";
  std::size_t drawn = 0;
  for (std::size_t i = 0; i < std::size_t{kWidth} * kHeight; ++i) {
    out.write(reinterpret_cast<const char*>(rgba + 4 * i), 3);
    drawn += rgba[4 * i] != 242 || rgba[4 * i + 1] != 242 || rgba[4 * i + 2] != 242;
  }
  readback_memory.unmapMemory();
  std::printf("%u particles after %d frames: %zu of %u pixels drawn; picture %s\n",
              particles->positions.count, frames, drawn, kWidth * kHeight, argv[2]);
  return 0;
} catch (const std::exception& e) {  // Vulkan-Hpp throws vk::SystemError for a failed call
  return fail(e.what());
}
