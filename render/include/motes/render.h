// Headless pictures of particles: a CPU ray-cast rasterizer of sphere impostors with a depth
// buffer, a ground plane with a grid and soft shadows, and PNG files (docs/rendering.md).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "motes/api.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "motes/status.h"

MOTES_API_BEGIN
namespace motes::render {

/// An 8-bit sRGB picture, rows top to bottom, 3 bytes (R, G, B) per pixel.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;

  /// The first of the 3 bytes of pixel (x, y); x to the right, y down from the top row.
  [[nodiscard]] const std::uint8_t* pixel(int x, int y) const {
    return rgb.data() + 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                             static_cast<std::size_t>(x));
  }
};

/// Picture size in pixels.
struct Size {
  int width = 1280;
  int height = 720;
};

/// Parses "WIDTHxHEIGHT" (e.g. "1280x720"), each from 16 to 16384; the error says what is wrong.
Result<Size> parse_size(const std::string& text);

/// What decides a particle's colour.
enum class ColorBy {
  Body,    ///< one colour per body: its "color" in the scene, else from a palette (fluids: water)
  Speed,   ///< particle speed through a colour map, 0 to the fastest speed seen so far
  Kind,    ///< dynamic bodies warm, static bodies grey, fluids water blue
  Height,  ///< height along "up" through the colour map, over the first frame's range
};

/// "body", "speed", "kind" or "height"; anything else is an error that lists them.
Result<ColorBy> parse_color_by(const std::string& name);
/// The names parse_color_by() accepts, comma-separated.
const char* color_by_names();

/// A pinhole camera. `fov_degrees` is the vertical field of view.
struct Camera {
  Eigen::Vector3f position{0.0f, 0.0f, 1.0f};
  Eigen::Vector3f target{0.0f, 0.0f, 0.0f};
  Eigen::Vector3f up{0.0f, 1.0f, 0.0f};
  float fov_degrees = 40.0f;
};

/// The camera of a scene file's "camera" key.
Camera camera_from_spec(const CameraSpec& spec);

/// A camera that looks at the particles' bounding box from the front, above and a little to the
/// side (along `up`), as close as keeps every sphere in a `size` picture, with a margin. With a
/// ground height, the box reaches down to the ground (where falling particles land).
Camera fit_camera(const std::vector<shared::vec4>& particles, const Eigen::Vector3f& up, Size size,
                  float fov_degrees = 35.0f, std::optional<float> ground_height = std::nullopt);

/// Where a world point lands in a `size` picture: pixel coordinates (x right, y down, pixel
/// (i, j) covers [i, i+1) x [j, j+1)) and the distance in front of the camera (<= 0: behind).
struct Projected {
  float x = 0.0f;
  float y = 0.0f;
  float depth = 0.0f;
};
Projected project(const Camera& camera, Size size, const Eigen::Vector3f& point);

/// What a picture shows besides the particles, and the facts about bodies that colours need.
struct SceneLook {
  Eigen::Vector3f up{0.0f, 1.0f, 0.0f};   ///< unit; the ground is perpendicular to it
  std::optional<float> ground_height;     ///< ground plane at up . x = height; none: no ground
  std::vector<std::uint8_t> body_static;  ///< 1 for a static body, by body index (may be short)
  /// A body's own colour (the scene's "color", sRGB 0..1), by body index (may be short).
  std::vector<std::optional<Eigen::Vector3f>> body_colors;
  std::vector<std::uint8_t> body_fluid;  ///< 1 for a fluid, by body index (may be short)
  float gravity = 9.81f;  ///< |g| (m/s^2; 0: none): the speed scale of a fluid's spray colour
};

/// The look of a loaded scene: up = -gravity (y when there is none), the ground = the plane whose
/// normal is up, if any, which bodies are static or fluid, and the bodies' own colours (bodies,
/// then cloths and ropes, then fluids: a Snapshot's body indices).
SceneLook look_from_scene(const Scene& scene);

/// Everything that stays the same from frame to frame.
struct RenderSettings {
  Size size;
  ColorBy color_by = ColorBy::Body;
  Camera camera;
  SceneLook look;
  bool shadows = true;  ///< soft shadows of the particles on the ground and on each other
};

/// The palette colour of body `index` (sRGB, 0..1).
Eigen::Vector3f body_color(std::uint32_t index);

/// The colour of a fluid without its own "color" (sRGB, 0..1): water blue.
Eigen::Vector3f water_color();

/// A particle's colour in pictures (sRGB, 0..1) by `color_by`: the rule the headless renderer and
/// `motes view` share. Speed colours scale by the fastest speed observed so far, height colours
/// by the first observed frame's range along the look's up.
///
/// Fluid particles (SceneLook::body_fluid) by body and by kind take their base colour (by body
/// the fluid's own colour, else water_color(); by kind water_color()) shaded per frame like water
/// (docs/rendering.md, "Colours of liquids"): darker with depth below the liquid's local surface
/// (the top of its run of particles in a column of 2 d x 2 d across up, d the diameter), lighter
/// in the top layer, and whiter where it moves fast (spray: from 2 to 6 sqrt(g d)).
class ParticleColors {
 public:
  ParticleColors(ColorBy color_by, SceneLook look);
  /// Takes `frame`'s fastest speed (when colouring by speed), the first time a frame has
  /// particles its height range, and (colouring by body or kind) its fluid particles' shading.
  void observe(const Snapshot& frame);
  /// The colour of particle `index` of `frame`, the frame last observed.
  [[nodiscard]] Eigen::Vector3f operator()(const Snapshot& frame, std::size_t index) const;
  /// The same without the per-frame shading of fluids (a fluid's base colour): for colours fixed
  /// once per scene (`motes view`'s zero-copy path).
  [[nodiscard]] Eigen::Vector3f unshaded(const Snapshot& frame, std::size_t index) const;
  /// Whether particle `index` of `frame` belongs to a fluid.
  [[nodiscard]] bool is_fluid(const Snapshot& frame, std::size_t index) const;
  [[nodiscard]] ColorBy color_by() const { return color_by_; }

  // The rule's data, for a GPU that applies it itself (motes view's zero-copy path): the colour
  // map's stops (sRGB; colours by speed and height interpolate them linearly over [0, 1] in equal
  // steps, clamped), the fastest speed observed so far, the height range (none before a frame
  // with particles) and the unit up it is measured along.
  static constexpr std::size_t kMapStops = 5;
  [[nodiscard]] static const std::array<Eigen::Vector3f, kMapStops>& map_stops();
  [[nodiscard]] float speed_max() const { return speed_max_; }
  [[nodiscard]] const std::optional<Eigen::Vector2f>& height_range() const { return height_range_; }
  [[nodiscard]] const Eigen::Vector3f& up() const { return look_.up; }

 private:
  /// The shading of `frame`'s fluid particles (fluid_state_), colouring by body or kind.
  void observe_fluids(const Snapshot& frame);

  ColorBy color_by_;
  SceneLook look_;
  float speed_max_ = 0.0f;
  std::optional<Eigen::Vector2f> height_range_;
  /// Per particle of the last observed frame (fluid particles only, else unused): the depth
  /// below the local surface in diameters, and the speed in units of sqrt(g d).
  std::vector<Eigen::Vector2f> fluid_state_;
};

/// Renders frames with fixed settings; buffers are kept between frames.
class FrameRenderer {
 public:
  explicit FrameRenderer(RenderSettings settings);
  ~FrameRenderer();
  FrameRenderer(const FrameRenderer&) = delete;
  FrameRenderer& operator=(const FrameRenderer&) = delete;

  /// Draws the particles of `frame` (positions with w = radius, velocities, body ids).
  /// The reference stays valid until the next call.
  const Image& render(const Snapshot& frame);

  [[nodiscard]] const RenderSettings& settings() const { return settings_; }

 private:
  struct Buffers;
  /// Colours row y of the picture from the depth buffer (shade_pass.cpp).
  void shade_row(const Snapshot& frame, int y);

  RenderSettings settings_;
  std::unique_ptr<Buffers> buffers_;
  ParticleColors colors_;
};

/// Writes `image` as a PNG file; the error names the file.
Status write_png(const std::string& path, const Image& image);

}  // namespace motes::render
MOTES_API_END
