// The window: GLFW for the window and input, a Vulkan swapchain drawn by the same Painter as the
// offscreen target, one frame in flight.
#include <volk.h>
// volk first: GLFW declares its Vulkan functions when the Vulkan types are known.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <fmt/format.h>

#include <algorithm>
#include <optional>

#include "motes/viewer.h"
#include "painter.h"

namespace motes::viewer {

namespace {

std::string glfw_error() {
  const char* text = nullptr;
  glfwGetError(&text);
  return text != nullptr ? text : "no reason given";
}

std::vector<const char*> window_extensions() {
  std::uint32_t count = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&count);
  if (names == nullptr) throw NoDisplay("GLFW finds no Vulkan window support: " + glfw_error());
  return {names, names + count};
}

}  // namespace

struct Window::Impl {
  Impl(render::Size s, const std::string& title, int wanted) : gpu(start(s, title)) {
    check(glfwCreateWindowSurface(gpu.instance, window, nullptr, &surface),
          "cannot make a Vulkan surface of the window");
    gpu.open(surface, wanted);
    particles.emplace(gpu);
    glfwSetWindowUserPointer(window, this);
    glfwSetScrollCallback(window, [](GLFWwindow* w, double /*x*/, double y) {
      static_cast<Impl*>(glfwGetWindowUserPointer(w))->input.zoom += static_cast<float>(y);
    });
    glfwSetKeyCallback(window,
                       [](GLFWwindow* w, int key, int /*scancode*/, int action, int /*mods*/) {
                         if (action != GLFW_PRESS) return;
                         Input& in = static_cast<Impl*>(glfwGetWindowUserPointer(w))->input;
                         switch (key) {
                           case GLFW_KEY_SPACE:
                             in.pause = true;
                             break;
                           case GLFW_KEY_PERIOD:
                             in.step = true;
                             break;
                           case GLFW_KEY_R:
                             in.reset = true;
                             break;
                           case GLFW_KEY_S:
                             in.slow_motion = true;
                             break;
                           case GLFW_KEY_P:
                             in.screenshot = true;
                             break;
                           case GLFW_KEY_V:
                             in.record = true;
                             break;
                           case GLFW_KEY_W:
                             in.grid_wireframe = true;
                             break;
                           case GLFW_KEY_C:
                             in.contact_wireframe = true;
                             break;
                           case GLFW_KEY_H:
                             in.shadows = true;
                             break;
                           case GLFW_KEY_ESCAPE:
                           case GLFW_KEY_Q:
                             in.quit = true;
                             break;
                           default:
                             break;
                         }
                       });
    VkSemaphoreCreateInfo sem{};
    sem.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    check(gpu.vk.vkCreateSemaphore(gpu.device, &sem, nullptr, &acquired), "vkCreateSemaphore");
    build_swapchain();
    gpu.check_messages();
  }

  /// glfwInit and the window, before the instance (which needs GLFW's extensions).
  std::vector<const char*> start(render::Size s, const std::string& title) {
    if (glfwInit() != GLFW_TRUE) throw NoDisplay(glfw_error());
    glfw_started = true;
    if (glfwVulkanSupported() != GLFW_TRUE) {
      throw NoDisplay("GLFW finds no Vulkan loader: " + glfw_error());
    }
    std::vector<const char*> exts = window_extensions();
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    window = glfwCreateWindow(s.width, s.height, title.c_str(), nullptr, nullptr);
    if (window == nullptr) throw NoDisplay("cannot open a window: " + glfw_error());
    return exts;
  }

  void build_swapchain() {
    VkSurfaceCapabilitiesKHR caps{};
    check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(gpu.physical, surface, &caps),
          "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
    int fb_width = 0, fb_height = 0;
    glfwGetFramebufferSize(window, &fb_width, &fb_height);
    extent = caps.currentExtent;
    if (extent.width == UINT32_MAX) {
      extent.width = std::clamp(static_cast<std::uint32_t>(std::max(fb_width, 1)),
                                caps.minImageExtent.width, caps.maxImageExtent.width);
      extent.height = std::clamp(static_cast<std::uint32_t>(std::max(fb_height, 1)),
                                 caps.minImageExtent.height, caps.maxImageExtent.height);
    }
    if (extent.width == 0 || extent.height == 0) return;  // minimized
    std::uint32_t count = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(gpu.physical, surface, &count, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(count);
    vkGetPhysicalDeviceSurfaceFormatsKHR(gpu.physical, surface, &count, formats.data());
    // UNORM: the shaders write gamma-2 values themselves, as the headless renderer stores them.
    VkSurfaceFormatKHR chosen{VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
    for (const VkSurfaceFormatKHR& f : formats) {
      if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) {
        chosen = f;
        break;
      }
    }
    if (chosen.format == VK_FORMAT_UNDEFINED) {
      throw std::runtime_error("viewer: the window offers no 8-bit UNORM RGBA or BGRA format");
    }
    if (!painter || chosen.format != format) {
      painter.reset();
      painter.emplace(gpu, *particles, chosen.format, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
      format = chosen.format;
    }
    can_copy = (caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) != 0;
    VkSwapchainCreateInfoKHR info{};
    info.sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR;
    info.surface = surface;
    info.minImageCount = std::max(caps.minImageCount, 2u);
    if (caps.maxImageCount > 0)
      info.minImageCount = std::min(info.minImageCount, caps.maxImageCount);
    info.imageFormat = chosen.format;
    info.imageColorSpace = chosen.colorSpace;
    info.imageExtent = extent;
    info.imageArrayLayers = 1;
    info.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                      (can_copy ? static_cast<VkImageUsageFlags>(VK_IMAGE_USAGE_TRANSFER_SRC_BIT)
                                : VkImageUsageFlags{0});
    info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.preTransform = caps.currentTransform;
    info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    info.presentMode = VK_PRESENT_MODE_FIFO_KHR;
    info.clipped = VK_TRUE;
    info.oldSwapchain = swapchain;
    VkSwapchainKHR made = VK_NULL_HANDLE;
    check(gpu.vk.vkCreateSwapchainKHR(gpu.device, &info, nullptr, &made), "vkCreateSwapchainKHR");
    drop_swapchain();
    swapchain = made;
    gpu.vk.vkGetSwapchainImagesKHR(gpu.device, swapchain, &count, nullptr);
    images.resize(count);
    gpu.vk.vkGetSwapchainImagesKHR(gpu.device, swapchain, &count, images.data());
    depth.emplace(gpu, painter->depth_format(), extent, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                  VK_IMAGE_ASPECT_DEPTH_BIT);
    VkSemaphoreCreateInfo sem{};
    sem.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    for (VkImage image : images) {
      VkImageViewCreateInfo view_info{};
      view_info.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
      view_info.image = image;
      view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
      view_info.format = format;
      view_info.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
      VkImageView view = VK_NULL_HANDLE;
      check(gpu.vk.vkCreateImageView(gpu.device, &view_info, nullptr, &view), "vkCreateImageView");
      views.push_back(view);
      framebuffers.push_back(
          make_framebuffer(gpu, painter->render_pass(), view, depth->view, extent));
      VkSemaphore done = VK_NULL_HANDLE;
      check(gpu.vk.vkCreateSemaphore(gpu.device, &sem, nullptr, &done), "vkCreateSemaphore");
      drawn.push_back(done);
    }
    readback.reset();
    if (can_copy) {
      readback.emplace(gpu, VkDeviceSize{4} * extent.width * extent.height,
                       VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    }
  }

  /// Everything made from the swapchain, and the old swapchain itself (after a new one is made).
  void drop_swapchain() {
    gpu.vk.vkDeviceWaitIdle(gpu.device);
    for (VkFramebuffer fb : framebuffers) gpu.vk.vkDestroyFramebuffer(gpu.device, fb, nullptr);
    for (VkImageView v : views) gpu.vk.vkDestroyImageView(gpu.device, v, nullptr);
    for (VkSemaphore s : drawn) gpu.vk.vkDestroySemaphore(gpu.device, s, nullptr);
    framebuffers.clear();
    views.clear();
    drawn.clear();
    images.clear();
    depth.reset();
    if (swapchain != VK_NULL_HANDLE) gpu.vk.vkDestroySwapchainKHR(gpu.device, swapchain, nullptr);
    swapchain = VK_NULL_HANDLE;
  }

  ~Impl() {
    if (gpu.device != VK_NULL_HANDLE) {
      drop_swapchain();
      readback.reset();
      painter.reset();
      particles.reset();
      if (acquired != VK_NULL_HANDLE) gpu.vk.vkDestroySemaphore(gpu.device, acquired, nullptr);
      if (command != VK_NULL_HANDLE) gpu.vk.vkFreeCommandBuffers(gpu.device, gpu.pool, 1, &command);
    }
    if (surface != VK_NULL_HANDLE) vkDestroySurfaceKHR(gpu.instance, surface, nullptr);
    if (window != nullptr) glfwDestroyWindow(window);
    if (glfw_started) glfwTerminate();
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  void draw(const render::Camera& camera, const Snapshot* frame, render::Image* screenshot) {
    if (!styler) throw std::logic_error("viewer: draw before restyle");
    if (!particles->attached() && frame == nullptr) {
      throw std::logic_error("viewer: a staged draw needs a frame");
    }
    if (resized) {
      resized = false;
      build_swapchain();
    }
    if (swapchain == VK_NULL_HANDLE || extent.width == 0) {
      build_swapchain();
      if (swapchain == VK_NULL_HANDLE) return;
    }
    std::uint32_t index = 0;
    VkResult r = gpu.vk.vkAcquireNextImageKHR(gpu.device, swapchain, UINT64_MAX, acquired,
                                              VK_NULL_HANDLE, &index);
    if (r == VK_ERROR_OUT_OF_DATE_KHR) {
      build_swapchain();
      return;
    }
    if (r != VK_SUBOPTIMAL_KHR) check(r, "vkAcquireNextImageKHR");
    if (!particles->attached()) particles->stage(*styler, *frame);
    particles->refresh();  // the CUDA path's copy (no draw of the last frame is in flight)
    if (command == VK_NULL_HANDLE) {
      VkCommandBufferAllocateInfo alloc{};
      alloc.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
      alloc.commandPool = gpu.pool;
      alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
      alloc.commandBufferCount = 1;
      check(gpu.vk.vkAllocateCommandBuffers(gpu.device, &alloc, &command),
            "vkAllocateCommandBuffers");
    }
    check(gpu.vk.vkResetCommandBuffer(command, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(gpu.vk.vkBeginCommandBuffer(command, &begin), "vkBeginCommandBuffer");
    const render::Size size{static_cast<int>(extent.width), static_cast<int>(extent.height)};
    painter->set_segments(overlay);
    painter->set_shadows(shadows);
    painter->record(command, framebuffers[index], extent, styler->constants(camera, size));
    const bool copy = screenshot != nullptr && readback.has_value();
    if (copy) {
      record_readback(gpu, command, images[index], VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, extent,
                      readback->buffer);
    }
    check(gpu.vk.vkEndCommandBuffer(command), "vkEndCommandBuffer");
    const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &acquired;
    submit.pWaitDstStageMask = &wait_stage;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &command;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &drawn[index];
    check(gpu.vk.vkQueueSubmit(gpu.queue, 1, &submit, gpu.fence), "vkQueueSubmit");
    VkPresentInfoKHR present{};
    present.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR;
    present.waitSemaphoreCount = 1;
    present.pWaitSemaphores = &drawn[index];
    present.swapchainCount = 1;
    present.pSwapchains = &swapchain;
    present.pImageIndices = &index;
    r = gpu.vk.vkQueuePresentKHR(gpu.queue, &present);
    // One frame in flight: the next frame rewrites the instance buffer and command buffer.
    check(gpu.vk.vkWaitForFences(gpu.device, 1, &gpu.fence, VK_TRUE, UINT64_MAX),
          "vkWaitForFences");
    check(gpu.vk.vkResetFences(gpu.device, 1, &gpu.fence), "vkResetFences");
    if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) {
      resized = true;
    } else {
      check(r, "vkQueuePresentKHR");
    }
    if (screenshot != nullptr) {
      if (!copy) throw std::runtime_error("viewer: this window's pictures cannot be read back");
      unpack_rgb(readback->mapped, extent, format == VK_FORMAT_B8G8R8A8_UNORM, *screenshot);
    }
    gpu.check_messages();
  }

  GLFWwindow* window = nullptr;
  bool glfw_started = false;
  Gpu gpu;
  std::optional<Styler> styler;
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{0, 0};
  bool can_copy = false;
  bool resized = false;
  std::optional<Particles> particles;  // before the painter, which draws them
  std::optional<Painter> painter;
  Segments overlay;     ///< the wireframe (set_overlay), given to the painter at each draw
  bool shadows = true;  ///< set_shadows, given to the painter at each draw
  std::optional<DeviceImage> depth;
  std::optional<HostBuffer> readback;
  std::vector<VkImage> images;
  std::vector<VkImageView> views;
  std::vector<VkFramebuffer> framebuffers;
  std::vector<VkSemaphore> drawn;
  VkSemaphore acquired = VK_NULL_HANDLE;
  VkCommandBuffer command = VK_NULL_HANDLE;
  Input input;
  double last_x = 0.0, last_y = 0.0;
  bool have_cursor = false;
  bool left_down = false;
  bool grabbing = false;
};

Window::Window(render::Size size, const std::string& title, int wanted_device)
    : impl_(std::make_unique<Impl>(size, title, wanted_device)) {}

Window::~Window() = default;

Input Window::poll() {
  Impl& m = *impl_;
  glfwPollEvents();
  double x = 0.0, y = 0.0;
  glfwGetCursorPos(m.window, &x, &y);
  const bool left = glfwGetMouseButton(m.window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
  const bool shift = glfwGetKey(m.window, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                     glfwGetKey(m.window, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
  // The cursor in drawable pixels (window coordinates scaled where they differ).
  int win_w = 0, win_h = 0, fb_w = 0, fb_h = 0;
  glfwGetWindowSize(m.window, &win_w, &win_h);
  glfwGetFramebufferSize(m.window, &fb_w, &fb_h);
  m.input.cursor_x = static_cast<float>(win_w > 0 ? x * fb_w / win_w : x);
  m.input.cursor_y = static_cast<float>(win_h > 0 ? y * fb_h / win_h : y);
  if (m.grabbing) {
    m.input.grabbing = true;
    if (!left) {
      m.input.grab_end = true;
      m.grabbing = false;
    }
  } else if (left && shift && !m.left_down) {
    m.grabbing = true;
    m.input.grab_start = m.input.grabbing = true;
  } else if (m.have_cursor) {
    const auto dx = static_cast<float>(x - m.last_x), dy = static_cast<float>(y - m.last_y);
    if (left) {
      m.input.orbit_x += dx;
      m.input.orbit_y += dy;
    } else if (glfwGetMouseButton(m.window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
               glfwGetMouseButton(m.window, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) {
      m.input.pan_x += dx;
      m.input.pan_y += dy;
    }
  }
  m.left_down = left;
  m.last_x = x;
  m.last_y = y;
  m.have_cursor = true;
  if (glfwWindowShouldClose(m.window) == GLFW_TRUE) m.input.quit = true;
  int w = 0, h = 0;
  glfwGetFramebufferSize(m.window, &w, &h);
  if (static_cast<std::uint32_t>(w) != m.extent.width ||
      static_cast<std::uint32_t>(h) != m.extent.height) {
    m.resized = true;
  }
  Input out = m.input;
  m.input = Input{};
  return out;
}

void Window::set_title(const std::string& title) {
  glfwSetWindowTitle(impl_->window, title.c_str());
}

render::Size Window::size() const {
  return {static_cast<int>(impl_->extent.width), static_cast<int>(impl_->extent.height)};
}

void Window::set_overlay(const Segments& segments) { impl_->overlay = segments; }

void Window::set_shadows(bool on) { impl_->shadows = on; }

void Window::draw(const render::Camera& camera, const Snapshot* frame, render::Image* screenshot) {
  impl_->draw(camera, frame, screenshot);
}

void Window::restyle(const Style& style, const Snapshot& first_frame) {
  impl_->styler.emplace(style, first_frame);
  impl_->particles->detach();
}

Result<std::unique_ptr<Device>> Window::open_compute_device() const {
  return viewer::open_compute_device(impl_->gpu);
}

std::string Window::attach(Simulation& sim, const Snapshot& first_frame) {
  if (!impl_->styler) throw std::logic_error("viewer: attach before restyle");
  std::string why = impl_->particles->attach(*impl_->styler, sim, first_frame);
  impl_->gpu.check_messages();
  return why;
}

bool Window::attached() const { return impl_->particles->attached(); }

const char* Window::path() const { return impl_->particles->path(); }

const std::string& Window::device_name() const { return impl_->gpu.name; }

int Window::device_index() const { return impl_->gpu.index; }

}  // namespace motes::viewer
