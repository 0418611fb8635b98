// Drawing without a window: a colour and a depth image, and the picture copied to the host.
#include <optional>

#include "motes/viewer.h"
#include "painter.h"

namespace motes::viewer {

struct Offscreen::Impl {
  static constexpr VkFormat kFormat = VK_FORMAT_R8G8B8A8_UNORM;

  Impl(render::Size s, const Style& style, const Snapshot& first)
      : size(s),
        extent{static_cast<std::uint32_t>(s.width), static_cast<std::uint32_t>(s.height)},
        gpu({}),
        styler(style, first) {
    gpu.open(VK_NULL_HANDLE);
    painter.emplace(gpu, kFormat, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    color.emplace(gpu, kFormat, extent,
                  VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                  VK_IMAGE_ASPECT_COLOR_BIT);
    depth.emplace(gpu, painter->depth_format(), extent, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                  VK_IMAGE_ASPECT_DEPTH_BIT);
    framebuffer = make_framebuffer(gpu, painter->render_pass(), color->view, depth->view, extent);
    readback.emplace(gpu, VkDeviceSize{4} * extent.width * extent.height,
                     VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    gpu.check_messages();
  }
  ~Impl() {
    gpu.vk.vkDeviceWaitIdle(gpu.device);
    if (framebuffer != VK_NULL_HANDLE)
      gpu.vk.vkDestroyFramebuffer(gpu.device, framebuffer, nullptr);
    readback.reset();
    depth.reset();
    color.reset();
    painter.reset();
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  render::Size size;
  VkExtent2D extent;
  Gpu gpu;
  Styler styler;
  std::optional<Painter> painter;
  std::optional<DeviceImage> color;
  std::optional<DeviceImage> depth;
  std::optional<HostBuffer> readback;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  std::vector<Instance> instances;
  render::Image image;
};

Offscreen::Offscreen(render::Size size, const Style& style, const Snapshot& first_frame)
    : impl_(std::make_unique<Impl>(size, style, first_frame)) {}

Offscreen::~Offscreen() = default;

const render::Image& Offscreen::draw(const render::Camera& camera, const Snapshot& frame) {
  Impl& m = *impl_;
  m.styler.instances(frame, m.instances);
  m.painter->upload(m.instances);
  VkCommandBuffer cmd = m.gpu.begin_commands();
  m.painter->record(cmd, m.framebuffer, m.extent, m.styler.constants(camera, m.size));
  record_readback(m.gpu, cmd, m.color->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, m.extent,
                  m.readback->buffer);
  m.gpu.submit_and_wait(cmd);
  unpack_rgb(m.readback->mapped, m.extent, false, m.image);
  return m.image;
}

const std::string& Offscreen::device_name() const { return impl_->gpu.name; }

}  // namespace motes::viewer
