// The graphics pipelines of the viewer and the copy of a picture back to the host.
#include "painter.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include "shaders.h"

namespace motes::viewer {

VkShaderModule make_module(const Gpu& gpu, std::string_view name) {
  for (const Shader& s : shader_table()) {
    if (name != s.name) continue;
    VkShaderModuleCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    info.codeSize = s.word_count * 4;
    info.pCode = s.words;
    VkShaderModule module = VK_NULL_HANDLE;
    check(gpu.vk.vkCreateShaderModule(gpu.device, &info, nullptr, &module), "vkCreateShaderModule");
    return module;
  }
  throw std::runtime_error(fmt::format("viewer: shader {} is not embedded", name));
}

namespace {

VkFormat pick_depth_format(const Gpu& gpu) {
  for (VkFormat f : {VK_FORMAT_D32_SFLOAT, VK_FORMAT_X8_D24_UNORM_PACK32, VK_FORMAT_D16_UNORM}) {
    VkFormatProperties props{};
    vkGetPhysicalDeviceFormatProperties(gpu.physical, f, &props);
    if ((props.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) != 0) {
      return f;
    }
  }
  throw std::runtime_error("viewer: the device has no depth format");
}

}  // namespace

Painter::Painter(const Gpu& gpu, const Particles& particles, VkFormat color_format,
                 VkImageLayout final_layout)
    : gpu_(gpu), particles_(particles), depth_format_(pick_depth_format(gpu)) {
  VkAttachmentDescription attachments[2]{};
  attachments[0].format = color_format;
  attachments[0].samples = VK_SAMPLE_COUNT_1_BIT;
  attachments[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  attachments[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  attachments[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  attachments[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  attachments[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  attachments[0].finalLayout = final_layout;
  attachments[1] = attachments[0];
  attachments[1].format = depth_format_;
  attachments[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  attachments[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  const VkAttachmentReference color_ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  const VkAttachmentReference depth_ref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &color_ref;
  subpass.pDepthStencilAttachment = &depth_ref;
  VkSubpassDependency deps[2]{};
  // Before: the last frame's reads of the colour image (copy, presentation engine through the
  // acquire semaphore's stage) and its depth writes.
  deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  deps[0].dstSubpass = 0;
  deps[0].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                         VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[0].srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  deps[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                         VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                         VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  deps[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  // After: the copy of the picture to the host.
  deps[1].srcSubpass = 0;
  deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkRenderPassCreateInfo pass{};
  pass.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
  pass.attachmentCount = 2;
  pass.pAttachments = attachments;
  pass.subpassCount = 1;
  pass.pSubpasses = &subpass;
  pass.dependencyCount = 2;
  pass.pDependencies = deps;
  check(gpu.vk.vkCreateRenderPass(gpu.device, &pass, nullptr, &render_pass_), "vkCreateRenderPass");

  VkPushConstantRange range{};
  range.stageFlags = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  range.size = sizeof(ViewConstants);
  const VkDescriptorSetLayout colors = particles.set_layout();
  VkPipelineLayoutCreateInfo layout{};
  layout.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  layout.setLayoutCount = 1;
  layout.pSetLayouts = &colors;
  layout.pushConstantRangeCount = 1;
  layout.pPushConstantRanges = &range;
  check(gpu.vk.vkCreatePipelineLayout(gpu.device, &layout, nullptr, &layout_),
        "vkCreatePipelineLayout");
  backdrop_ = make_pipeline("backdrop.vert", "backdrop.frag", Kind::Backdrop);
  shadows_ = make_pipeline("shadow.vert", "shadow.frag", Kind::Shadows);
  spheres_ = make_pipeline("sphere.vert", "sphere.frag", Kind::Spheres);
  lines_ = make_pipeline("lines.vert", "lines.frag", Kind::Lines);
}

void Painter::set_segments(const Segments& segments) {
  // Two vec4 a point: position, then its segment's colour (lines.vert).
  const std::size_t points = std::min(segments.ends.size(), 2 * segments.colors.size());
  const VkDeviceSize bytes = std::max<VkDeviceSize>(points, 1) * 2 * sizeof(Vec4);
  if (!segments_ || segments_->size < bytes) {
    segments_.reset();
    segments_ = std::make_unique<HostBuffer>(gpu_, bytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  }
  auto* out = static_cast<float*>(segments_->mapped);
  for (std::size_t k = 0; k < points; ++k) {
    const Eigen::Vector3f& p = segments.ends[k];
    const Eigen::Vector3f& c = segments.colors[k / 2];
    const float v[8] = {p.x(), p.y(), p.z(), 1.0f, c.x(), c.y(), c.z(), 1.0f};
    std::copy(v, v + 8, out + 8 * k);
  }
  segment_points_ = static_cast<std::uint32_t>(points);
}

VkPipeline Painter::make_pipeline(const char* vert, const char* frag, Kind kind) const {
  const bool spheres = kind == Kind::Spheres;
  const bool shadows = kind == Kind::Shadows;
  const bool lines = kind == Kind::Lines;
  const VkShaderModule vs = make_module(gpu_, vert);
  const VkShaderModule fs = make_module(gpu_, frag);
  VkPipelineShaderStageCreateInfo stages[2]{};
  stages[0].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = vs;
  stages[0].pName = "main";
  stages[1] = stages[0];
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = fs;

  // Two per-instance arrays of vec4 (particles.h): the spheres, and their colours or velocities;
  // motes' ParticlePos and ParticleVel have this layout, so the zero-copy path binds them as
  // they are.
  const VkVertexInputBindingDescription bindings[2] = {
      {0, sizeof(Vec4), VK_VERTEX_INPUT_RATE_INSTANCE},
      {1, sizeof(Vec4), VK_VERTEX_INPUT_RATE_INSTANCE}};
  const VkVertexInputAttributeDescription attributes[2] = {
      {0, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 0}, {1, 1, VK_FORMAT_R32G32B32A32_SFLOAT, 0}};
  // A wireframe's points: one array of position and colour pairs (set_segments).
  const VkVertexInputBindingDescription line_binding{0, 2 * sizeof(Vec4),
                                                     VK_VERTEX_INPUT_RATE_VERTEX};
  const VkVertexInputAttributeDescription line_attributes[2] = {
      {0, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 0},
      {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(Vec4)}};
  VkPipelineVertexInputStateCreateInfo input{};
  input.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
  if (spheres) {
    input.vertexBindingDescriptionCount = 2;
    input.pVertexBindingDescriptions = bindings;
    input.vertexAttributeDescriptionCount = 2;
    input.pVertexAttributeDescriptions = attributes;
  } else if (shadows) {
    // The spheres alone: the draw binds the colours too (Particles::record_draw), unread.
    input.vertexBindingDescriptionCount = 1;
    input.pVertexBindingDescriptions = bindings;
    input.vertexAttributeDescriptionCount = 1;
    input.pVertexAttributeDescriptions = attributes;
  } else if (lines) {
    input.vertexBindingDescriptionCount = 1;
    input.pVertexBindingDescriptions = &line_binding;
    input.vertexAttributeDescriptionCount = 2;
    input.pVertexAttributeDescriptions = line_attributes;
  }
  VkPipelineInputAssemblyStateCreateInfo assembly{};
  assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
  assembly.topology = spheres || shadows ? VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP
                      : lines            ? VK_PRIMITIVE_TOPOLOGY_LINE_LIST
                                         : VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo viewport{};
  viewport.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
  viewport.viewportCount = 1;
  viewport.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo raster{};
  raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = VK_CULL_MODE_NONE;
  raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  raster.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo multisample{};
  multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo depth{};
  depth.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
  // A wireframe is drawn over everything (a contact's segment lies inside its two spheres).
  // Depth is near / distance: greater is nearer, 0 as cleared. The spheres go first; the
  // shadows, on the ground, where no sphere is in front (they leave the depth as it is); the
  // backdrop last, where no sphere is in front of the ground (the sky, at depth 0, where none
  // is).
  depth.depthTestEnable = lines ? VK_FALSE : VK_TRUE;
  depth.depthWriteEnable = lines || shadows ? VK_FALSE : VK_TRUE;
  depth.depthCompareOp =
      kind == Kind::Backdrop ? VK_COMPARE_OP_GREATER_OR_EQUAL : VK_COMPARE_OP_GREATER;
  VkPipelineColorBlendAttachmentState blend{};
  blend.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                         VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
  if (shadows) {
    // The light left on the ground (shadow.frag), the least of overlapping shadows' (MIN does
    // not use the factors), in alpha alone.
    blend.colorWriteMask = VK_COLOR_COMPONENT_A_BIT;
    blend.blendEnable = VK_TRUE;
    blend.srcColorBlendFactor = blend.dstColorBlendFactor = VK_BLEND_FACTOR_ONE;
    blend.srcAlphaBlendFactor = blend.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    blend.colorBlendOp = blend.alphaBlendOp = VK_BLEND_OP_MIN;
  } else if (kind == Kind::Backdrop) {
    // The sky and ground times that light (1, as cleared, where there is no shadow); alpha 1.
    blend.blendEnable = VK_TRUE;
    blend.srcColorBlendFactor = VK_BLEND_FACTOR_DST_ALPHA;
    blend.dstColorBlendFactor = VK_BLEND_FACTOR_ZERO;
    blend.colorBlendOp = VK_BLEND_OP_ADD;
    blend.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    blend.dstAlphaBlendFactor = VK_BLEND_FACTOR_ZERO;
    blend.alphaBlendOp = VK_BLEND_OP_ADD;
  }
  VkPipelineColorBlendStateCreateInfo blending{};
  blending.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
  blending.attachmentCount = 1;
  blending.pAttachments = &blend;
  const VkDynamicState dynamic_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dynamic{};
  dynamic.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
  dynamic.dynamicStateCount = 2;
  dynamic.pDynamicStates = dynamic_states;

  VkGraphicsPipelineCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
  info.stageCount = 2;
  info.pStages = stages;
  info.pVertexInputState = &input;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &viewport;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &multisample;
  info.pDepthStencilState = &depth;
  info.pColorBlendState = &blending;
  info.pDynamicState = &dynamic;
  info.layout = layout_;
  info.renderPass = render_pass_;
  VkPipeline pipeline = VK_NULL_HANDLE;
  const VkResult r =
      gpu_.vk.vkCreateGraphicsPipelines(gpu_.device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline);
  gpu_.vk.vkDestroyShaderModule(gpu_.device, vs, nullptr);
  gpu_.vk.vkDestroyShaderModule(gpu_.device, fs, nullptr);
  check(r, "vkCreateGraphicsPipelines");
  return pipeline;
}

void Painter::record(VkCommandBuffer cmd, VkFramebuffer framebuffer, VkExtent2D extent,
                     const ViewConstants& constants) const {
  VkClearValue clears[2]{};
  clears[0].color = {{0.0f, 0.0f, 0.0f, 1.0f}};
  clears[1].depthStencil = {0.0f, 0};
  particles_.record_before(cmd);
  VkRenderPassBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  begin.renderPass = render_pass_;
  begin.framebuffer = framebuffer;
  begin.renderArea.extent = extent;
  begin.clearValueCount = 2;
  begin.pClearValues = clears;
  gpu_.vk.vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
  const VkViewport viewport{
      0.0f, 0.0f, static_cast<float>(extent.width), static_cast<float>(extent.height), 0.0f, 1.0f};
  const VkRect2D scissor{{0, 0}, extent};
  gpu_.vk.vkCmdSetViewport(cmd, 0, 1, &viewport);
  gpu_.vk.vkCmdSetScissor(cmd, 0, 1, &scissor);
  gpu_.vk.vkCmdPushConstants(cmd, layout_,
                             VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                             sizeof(ViewConstants), constants.v.data());
  // The spheres; the shadows into the cleared alpha where no sphere hides the ground (grid_x.w,
  // view.glsl: 1 when the scene has a ground); the backdrop scaled by it.
  gpu_.vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, spheres_);
  particles_.record_draw(cmd, layout_);
  if (shadows_on_ && constants.v[31] > 0.5f) {
    gpu_.vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, shadows_);
    particles_.record_draw(cmd, layout_);
  }
  gpu_.vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, backdrop_);
  gpu_.vk.vkCmdDraw(cmd, 3, 1, 0, 0);
  if (segment_points_ > 0) {
    gpu_.vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, lines_);
    const VkDeviceSize offset = 0;
    gpu_.vk.vkCmdBindVertexBuffers(cmd, 0, 1, &segments_->buffer, &offset);
    gpu_.vk.vkCmdDraw(cmd, segment_points_, 1, 0, 0);
  }
  gpu_.vk.vkCmdEndRenderPass(cmd);
  particles_.record_after(cmd);
}

Painter::~Painter() {
  gpu_.vk.vkDeviceWaitIdle(gpu_.device);
  if (lines_ != VK_NULL_HANDLE) gpu_.vk.vkDestroyPipeline(gpu_.device, lines_, nullptr);
  if (spheres_ != VK_NULL_HANDLE) gpu_.vk.vkDestroyPipeline(gpu_.device, spheres_, nullptr);
  if (shadows_ != VK_NULL_HANDLE) gpu_.vk.vkDestroyPipeline(gpu_.device, shadows_, nullptr);
  if (backdrop_ != VK_NULL_HANDLE) gpu_.vk.vkDestroyPipeline(gpu_.device, backdrop_, nullptr);
  if (layout_ != VK_NULL_HANDLE) gpu_.vk.vkDestroyPipelineLayout(gpu_.device, layout_, nullptr);
  if (render_pass_ != VK_NULL_HANDLE) {
    gpu_.vk.vkDestroyRenderPass(gpu_.device, render_pass_, nullptr);
  }
}

VkFramebuffer make_framebuffer(const Gpu& gpu, VkRenderPass pass, VkImageView color,
                               VkImageView depth, VkExtent2D extent) {
  const VkImageView views[2] = {color, depth};
  VkFramebufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
  info.renderPass = pass;
  info.attachmentCount = 2;
  info.pAttachments = views;
  info.width = extent.width;
  info.height = extent.height;
  info.layers = 1;
  VkFramebuffer fb = VK_NULL_HANDLE;
  check(gpu.vk.vkCreateFramebuffer(gpu.device, &info, nullptr, &fb), "vkCreateFramebuffer");
  return fb;
}

void record_readback(const Gpu& gpu, VkCommandBuffer cmd, VkImage image, VkImageLayout layout,
                     VkExtent2D extent, VkBuffer buffer) {
  VkImageMemoryBarrier to_copy{};
  to_copy.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  to_copy.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  to_copy.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  to_copy.oldLayout = layout;
  to_copy.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  to_copy.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  to_copy.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  to_copy.image = image;
  to_copy.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  const bool transition = layout != VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  if (transition) {
    gpu.vk.vkCmdPipelineBarrier(
        cmd, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
        VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &to_copy);
  }
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {extent.width, extent.height, 1};
  gpu.vk.vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1,
                                &region);
  if (transition) {
    VkImageMemoryBarrier back = to_copy;
    back.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    back.dstAccessMask = 0;
    back.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    back.newLayout = layout;
    gpu.vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                                VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, nullptr, 0, nullptr, 1,
                                &back);
  }
  VkBufferMemoryBarrier to_host{};
  to_host.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
  to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  to_host.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  to_host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  to_host.buffer = buffer;
  to_host.size = VK_WHOLE_SIZE;
  gpu.vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0,
                              nullptr, 1, &to_host, 0, nullptr);
}

void unpack_rgb(const void* mapped, VkExtent2D extent, bool bgra, render::Image& out) {
  out.width = static_cast<int>(extent.width);
  out.height = static_cast<int>(extent.height);
  const std::size_t pixels = static_cast<std::size_t>(extent.width) * extent.height;
  out.rgb.resize(3 * pixels);
  const auto* src = static_cast<const std::uint8_t*>(mapped);
  for (std::size_t i = 0; i < pixels; ++i) {
    out.rgb[3 * i] = src[4 * i + (bgra ? 2 : 0)];
    out.rgb[3 * i + 1] = src[4 * i + 1];
    out.rgb[3 * i + 2] = src[4 * i + (bgra ? 0 : 2)];
  }
}

}  // namespace motes::viewer
