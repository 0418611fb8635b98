// Built without GLFW: the window is refused with a one-line reason (offscreen drawing remains).
#include "motes/viewer.h"

namespace motes::viewer {

struct Window::Impl {};

Window::Window(render::Size /*size*/, const std::string& /*title*/, const Style& /*style*/,
               const Snapshot& /*first_frame*/) {
  throw NoDisplay("built without GLFW (Debian: libglfw3-dev)");
}
Window::~Window() = default;
Input Window::poll() { return {}; }
void Window::set_title(const std::string& /*title*/) {}
render::Size Window::size() const { return {}; }
void Window::draw(const render::Camera& /*camera*/, const Snapshot& /*frame*/,
                  render::Image* /*screenshot*/) {}
void Window::restyle(const Style& /*style*/, const Snapshot& /*first_frame*/) {}
const std::string& Window::device_name() const {
  static const std::string none;
  return none;
}

}  // namespace motes::viewer
