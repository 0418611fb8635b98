// The render pass and the four pipelines (shadows: what the particles' shadows leave of the
// ground's light; backdrop: sky and ground; spheres: one quad per particle; lines: a wireframe over
// the picture), and the copy of a drawn picture to the host.
#pragma once

#include <memory>
#include <string_view>
#include <vector>

#include "gpu.h"
#include "motes/render.h"
#include "motes/viewer.h"
#include "particles.h"
#include "style.h"

namespace motes::viewer {

/// A shader module of the embedded shader `name` (e.g. "sphere.vert").
VkShaderModule make_module(const Gpu& gpu, std::string_view name);

class Painter {
 public:
  /// For colour attachments of `color_format`, left in `final_layout` after the pass; the
  /// spheres from `particles` (whose colour set the sphere pipeline reads).
  Painter(const Gpu& gpu, const Particles& particles, VkFormat color_format,
          VkImageLayout final_layout);
  ~Painter();
  Painter(const Painter&) = delete;
  Painter& operator=(const Painter&) = delete;

  /// The wireframe drawn over the spheres from the next record on (none when empty). The previous
  /// draw must be done.
  void set_segments(const Segments& segments);
  /// Whether the particles' shadows are drawn on the ground (when the scene has one).
  void set_shadows(bool on) { shadows_on_ = on; }
  /// Records what the particles need before the pass, then the pass: clear, spheres, shadows,
  /// backdrop, the wireframe.
  void record(VkCommandBuffer cmd, VkFramebuffer framebuffer, VkExtent2D extent,
              const ViewConstants& constants) const;

  [[nodiscard]] VkRenderPass render_pass() const { return render_pass_; }
  [[nodiscard]] VkFormat depth_format() const { return depth_format_; }

 private:
  enum class Kind { Backdrop, Shadows, Spheres, Lines };
  VkPipeline make_pipeline(const char* vert, const char* frag, Kind kind) const;

  const Gpu& gpu_;
  const Particles& particles_;
  VkFormat depth_format_ = VK_FORMAT_UNDEFINED;
  VkRenderPass render_pass_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline backdrop_ = VK_NULL_HANDLE;
  VkPipeline shadows_ = VK_NULL_HANDLE;
  VkPipeline spheres_ = VK_NULL_HANDLE;
  VkPipeline lines_ = VK_NULL_HANDLE;
  std::unique_ptr<HostBuffer> segments_;  ///< the wireframe's points (set_segments)
  std::uint32_t segment_points_ = 0;
  bool shadows_on_ = true;
};

/// A framebuffer of a colour view and a depth view.
VkFramebuffer make_framebuffer(const Gpu& gpu, VkRenderPass pass, VkImageView color,
                               VkImageView depth, VkExtent2D extent);

/// Records the copy of `image` (in `layout`, left in `layout`) into `buffer`, tightly packed
/// 4 bytes a pixel, and makes it visible to the host.
void record_readback(const Gpu& gpu, VkCommandBuffer cmd, VkImage image, VkImageLayout layout,
                     VkExtent2D extent, VkBuffer buffer);
/// The picture in `mapped` (4 bytes a pixel, RGBA or with `bgra` BGRA) as an RGB image.
void unpack_rgb(const void* mapped, VkExtent2D extent, bool bgra, render::Image& out);

}  // namespace motes::viewer
