// Built without GLFW: the window is refused with a one-line reason (offscreen drawing remains).
#include "motes/viewer.h"

namespace motes::viewer {

struct Window::Impl {};

Window::Window(render::Size /*size*/, const std::string& /*title*/, int /*wanted_device*/) {
  throw NoDisplay("built without GLFW (Debian: libglfw3-dev)");
}
Window::~Window() = default;
Input Window::poll() { return {}; }
void Window::set_title(const std::string& /*title*/) {}
render::Size Window::size() const { return {}; }
void Window::draw(const render::Camera& /*camera*/, const Snapshot* /*frame*/,
                  render::Image* /*screenshot*/) {}
void Window::set_overlay(const Segments& /*segments*/) {}
void Window::set_shadows(bool /*on*/) {}
void Window::restyle(const Style& /*style*/, const Snapshot& /*first_frame*/) {}
Result<std::unique_ptr<Device>> Window::open_compute_device() const {
  return Status::error("built without GLFW");
}
std::string Window::attach(Simulation& /*sim*/, const Snapshot& /*first_frame*/) {
  return "built without GLFW";
}
bool Window::attached() const { return false; }
const char* Window::path() const { return "staged"; }
const std::string& Window::device_name() const {
  static const std::string none;
  return none;
}
int Window::device_index() const { return -1; }

}  // namespace motes::viewer
