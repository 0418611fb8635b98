// Drawing without a window: a colour and a depth image, and the picture copied to the host.
#include <optional>
#include <stdexcept>

#include "motes/viewer.h"
#include "painter.h"

namespace motes::viewer {

struct Offscreen::Impl {
  static constexpr VkFormat kFormat = VK_FORMAT_R8G8B8A8_UNORM;

  Impl(render::Size s, int wanted)
      : size(s),
        extent{static_cast<std::uint32_t>(s.width), static_cast<std::uint32_t>(s.height)},
        gpu({}) {
    gpu.open(VK_NULL_HANDLE, wanted);
    particles.emplace(gpu);
    painter.emplace(gpu, *particles, kFormat, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
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
    particles.reset();
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  render::Size size;
  VkExtent2D extent;
  Gpu gpu;
  std::optional<Styler> styler;
  std::optional<Particles> particles;
  std::optional<Painter> painter;
  Segments overlay;     ///< the wireframe (set_overlay), given to the painter at each draw
  bool shadows = true;  ///< set_shadows, given to the painter at each draw
  std::optional<DeviceImage> color;
  std::optional<DeviceImage> depth;
  std::optional<HostBuffer> readback;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  render::Image image;
};

Offscreen::Offscreen(render::Size size, int wanted_device)
    : impl_(std::make_unique<Impl>(size, wanted_device)) {}

Offscreen::~Offscreen() = default;

void Offscreen::restyle(const Style& style, const Snapshot& first_frame) {
  impl_->styler.emplace(style, first_frame);
  impl_->particles->detach();
}

Result<std::unique_ptr<Device>> Offscreen::open_compute_device() const {
  return viewer::open_compute_device(impl_->gpu);
}

std::string Offscreen::attach(Simulation& sim, const Snapshot& first_frame) {
  if (!impl_->styler) throw std::logic_error("viewer: attach before restyle");
  std::string why = impl_->particles->attach(*impl_->styler, sim, first_frame);
  impl_->gpu.check_messages();
  return why;
}

bool Offscreen::attached() const { return impl_->particles->attached(); }

const char* Offscreen::path() const { return impl_->particles->path(); }

const render::Image& Offscreen::draw(const render::Camera& camera, const Snapshot* frame) {
  Impl& m = *impl_;
  if (!m.styler) throw std::logic_error("viewer: draw before restyle");
  if (!m.particles->attached()) {
    if (frame == nullptr) throw std::logic_error("viewer: a staged draw needs a frame");
    m.particles->stage(*m.styler, *frame);
  }
  m.particles->refresh();  // the CUDA path's copy
  VkCommandBuffer cmd = m.gpu.begin_commands();
  m.painter->set_segments(m.overlay);
  m.painter->set_shadows(m.shadows);
  m.painter->record(cmd, m.framebuffer, m.extent, m.styler->constants(camera, m.size));
  record_readback(m.gpu, cmd, m.color->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, m.extent,
                  m.readback->buffer);
  m.gpu.submit_and_wait(cmd);
  unpack_rgb(m.readback->mapped, m.extent, false, m.image);
  return m.image;
}

void Offscreen::set_overlay(const Segments& segments) { impl_->overlay = segments; }

void Offscreen::set_shadows(bool on) { impl_->shadows = on; }

const std::string& Offscreen::device_name() const { return impl_->gpu.name; }

int Offscreen::device_index() const { return impl_->gpu.index; }

}  // namespace motes::viewer
