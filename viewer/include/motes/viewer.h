// The interactive viewer's drawing (docs/viewer.md): particles as lit sphere impostors and the
// ground with its grid, drawn by a Vulkan graphics pipeline into an offscreen picture or a GLFW
// window, in the headless renderer's picture conventions (motes/render.h) so that both pictures
// of one state line up. Errors are thrown as std::runtime_error with a one-line message (Vulkan
// validation messages, when MOTES_VULKAN_VALIDATION is set, are errors too).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "motes/render.h"
#include "motes/simulation.h"

namespace motes::viewer {

/// What the pictures show besides the particles' positions, and how particles are coloured.
struct Style {
  render::SceneLook look;
  render::ColorBy color_by = render::ColorBy::Body;
};

/// Line segments drawn over the picture (the wireframes of `motes view`'s W and C keys): segment k
/// runs from ends[2k] to ends[2k + 1] in colors[k] (linear RGB).
struct Segments {
  std::vector<Eigen::Vector3f> ends;
  std::vector<Eigen::Vector3f> colors;
  bool truncated = false;  ///< the limit it was made with was reached: some are left out
};

/// The cells of the collision grid (a cell holds the points x with floor(x * inv_cell_size) equal,
/// as the simulation's StepParams) that hold a particle centre of `frame`, each as its 12 edges;
/// the first `max_cells` cells met in particle order.
Segments grid_cell_segments(const Snapshot& frame, float inv_cell_size, std::size_t max_cells);
/// Every pair of particles of different bodies that touch in `frame` (centres closer than 1.01
/// times the sum of the radii), as the segment between their centres; at most `max_contacts`.
Segments contact_segments(const Snapshot& frame, std::size_t max_contacts);

// Offscreen and Window draw the particles by one of three paths (docs/viewer.md): staged, from a
// Snapshot each frame (any backend); zero copy, from the buffers of a simulation that runs on
// the viewer's own Vulkan device (open_compute_device, then attach); or the CUDA copy, from
// memory the viewer shares with a CUDA simulation on the same GPU (attach). Before the first draw,
// and after each new scene, restyle() gives the colours and the ground; it returns to the staged
// path until attach() is called again.

/// Draws into an offscreen colour and depth image and reads the picture back.
class Offscreen {
 public:
  /// On Vulkan physical device `wanted_device` (the loader's order) when it can draw, else on the
  /// best one that can.
  explicit Offscreen(render::Size size, int wanted_device = -1);
  ~Offscreen();
  Offscreen(const Offscreen&) = delete;
  Offscreen& operator=(const Offscreen&) = delete;

  /// The ground's extent and grid, and the height colours, come from `first_frame` (as the
  /// headless renderer takes them from the first frame it draws).
  void restyle(const Style& style, const Snapshot& first_frame);
  /// A motes device on the viewer's Vulkan device (motes/vulkan_interop.h), or why not.
  [[nodiscard]] Result<std::unique_ptr<Device>> open_compute_device() const;
  /// Draws `sim` (`first_frame`: its state now) without the host until the next restyle: zero
  /// copy from its own buffers when it runs on a device from open_compute_device; or, when it
  /// runs on CUDA on the viewer's GPU, from memory the viewer shares with CUDA, which copies the
  /// particles in device to device before each draw. Returns why neither can be (empty when
  /// attached); the draws stay staged then.
  std::string attach(Simulation& sim, const Snapshot& first_frame);
  [[nodiscard]] bool attached() const;
  /// How the particles come to the picture: "zero copy", "CUDA copy" or "staged".
  [[nodiscard]] const char* path() const;
  /// Draws `frame` (staged; ignored, and may be null, when attached) seen by `camera`; the
  /// reference stays valid until the next call.
  const render::Image& draw(const render::Camera& camera, const Snapshot* frame);
  /// The wireframe drawn over the particles from the next draw on (none when empty).
  void set_overlay(const Segments& segments);
  /// Whether the next draws cast the particles' shadows on the ground (when the scene has one;
  /// on until set).
  void set_shadows(bool on);
  /// The Vulkan device that draws, and its place in the loader's order.
  [[nodiscard]] const std::string& device_name() const;
  [[nodiscard]] int device_index() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// No window can be opened: no display, or GLFW could not start. Its message is one line.
struct NoDisplay : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// What the person did since the last poll.
struct Input {
  float orbit_x = 0.0f;  ///< pixels dragged with the left button
  float orbit_y = 0.0f;
  float pan_x = 0.0f;  ///< pixels dragged with the right or middle button
  float pan_y = 0.0f;
  float zoom = 0.0f;               ///< wheel steps (positive: towards the target)
  bool pause = false;              ///< Space
  bool step = false;               ///< .
  bool reset = false;              ///< R
  bool slow_motion = false;        ///< S
  bool screenshot = false;         ///< P
  bool record = false;             ///< V: start or stop recording a video
  bool grid_wireframe = false;     ///< W: the collision grid's occupied cells on or off
  bool contact_wireframe = false;  ///< C: the contacts on or off
  bool shadows = false;            ///< H: the shadows on the ground on or off
  bool quit = false;               ///< Esc, Q or the window closed
  /// Shift + left button: grab (pick and drag). grab_start on the press, grabbing while held
  /// (the press's frame too), grab_end on the release; the cursor in drawable pixels (x right, y
  /// down, as the pictures' pixel centres at i + 0.5).
  bool grab_start = false;
  bool grabbing = false;
  bool grab_end = false;
  float cursor_x = 0.0f;
  float cursor_y = 0.0f;

  /// Adds `other`'s movements and presses to these (a script's events to the window's).
  void merge(const Input& other);
};

/// Scripted input (`motes view --input FILE`, docs/viewer.md): timed events by frame number, one
/// a line, turned into the same Input a person's keys and mouse give. Lines: `FRAME key NAME`
/// (space, period or ., r, s, p, v, w, c, h, q, escape), `FRAME wheel STEPS`, `FRAME drag X0 Y0 X1
/// Y1 N [left|right|middle|shift]` (pressed at pixel (X0, Y0), moved evenly to (X1, Y1) over the N
/// frames after FRAME, released at FRAME + N; shift: Shift + left, a grab), `FRAME quit`; `#`
/// starts a comment.
class Script {
 public:
  /// Reads `path`; throws std::runtime_error "FILE:LINE: reason" for a bad line.
  static Script load(const std::string& path);
  /// Parses `text` (named `name` in error messages).
  static Script parse(const std::string& text, const std::string& name);
  /// The input of frame `frame` (0 is the first frame shown).
  [[nodiscard]] Input at(std::uint64_t frame) const;
  /// Whether some event quits (so that a run needs no frame limit).
  [[nodiscard]] bool quits() const;

 private:
  struct Event {
    std::uint64_t frame = 0;
    Input input;
  };
  std::vector<Event> events_;
};

/// A GLFW window with a Vulkan swapchain.
class Window {
 public:
  /// Opens a window of `size` pixels, drawn on Vulkan physical device `wanted_device` when it
  /// can, else on the best one that can; throws NoDisplay when there is no display.
  Window(render::Size size, const std::string& title, int wanted_device = -1);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  /// Handles the window system's events and returns what the person did.
  Input poll();
  void set_title(const std::string& title);
  /// The drawable size in pixels (changes when the window is resized).
  [[nodiscard]] render::Size size() const;
  /// Draws `frame` (staged; ignored, and may be null, when attached) and shows it; with
  /// `screenshot`, also reads the shown picture back into it.
  void draw(const render::Camera& camera, const Snapshot* frame, render::Image* screenshot);
  /// The wireframe drawn over the particles from the next draw on (none when empty).
  void set_overlay(const Segments& segments);
  /// As Offscreen's.
  void set_shadows(bool on);
  /// Colours and extent of a scene (as Offscreen::restyle).
  void restyle(const Style& style, const Snapshot& first_frame);
  /// As Offscreen's.
  [[nodiscard]] Result<std::unique_ptr<Device>> open_compute_device() const;
  std::string attach(Simulation& sim, const Snapshot& first_frame);
  [[nodiscard]] bool attached() const;
  [[nodiscard]] const char* path() const;
  [[nodiscard]] const std::string& device_name() const;
  [[nodiscard]] int device_index() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Mouse camera control around a target: orbit about `up`, pan across the view, zoom in and out.
/// Until moved, camera() is the starting camera exactly.
class Orbit {
 public:
  explicit Orbit(const render::Camera& start);
  void orbit(float dx_pixels, float dy_pixels);
  void pan(float dx_pixels, float dy_pixels, render::Size size);
  void zoom(float steps);
  [[nodiscard]] render::Camera camera() const;

 private:
  render::Camera start_;
  bool moved_ = false;
  Eigen::Vector3f target_;
  Eigen::Vector3f up_;
  float distance_ = 1.0f;
  float azimuth_ = 0.0f;    ///< radians about up, from the ground's z axis towards its x axis
  float elevation_ = 0.0f;  ///< radians above the ground
  float fov_degrees_ = 40.0f;
};

}  // namespace motes::viewer
