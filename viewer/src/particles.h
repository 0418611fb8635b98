// Where the sphere pipeline's particles come from (docs/viewer.md, "How it draws"): staged, a
// snapshot's positions and colours copied through the host each frame; or zero copy, the
// simulation's own Vulkan buffers on the viewer's device (motes/vulkan_interop.h), read by the
// vertex stage, with body and kind colours uploaded once and speed and height colours made on
// the GPU (colors.glsl, speed_max.comp).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "cuda_share.h"
#include "gpu.h"
#include "motes/simulation.h"
#include "style.h"

namespace motes::viewer {

class Particles {
 public:
  explicit Particles(const Gpu& gpu);
  ~Particles();
  Particles(const Particles&) = delete;
  Particles& operator=(const Particles&) = delete;

  /// Staged: the finite particles of `frame` and their colours (leaves the zero-copy path).
  void stage(Styler& styler, const Snapshot& frame);
  /// From now on without the host: zero copy, `sim`'s own buffers when it runs on this Gpu's
  /// device; or the CUDA path, its particles copied by CUDA into memory shared with this Gpu
  /// (cuda_share.h) when it runs on CUDA on the same GPU. `first_frame` (its state now) gives
  /// body and kind colours. Again after every Simulation::create. Returns why neither path can
  /// draw `sim` (empty when attached), left on the staged path then.
  std::string attach(const Styler& styler, Simulation& sim, const Snapshot& first_frame);
  /// Back to the staged path (a new scene: its simulation's buffers are not these).
  void detach();
  [[nodiscard]] bool attached() const { return direct_.has_value(); }
  /// "zero copy", "CUDA copy" or "staged".
  [[nodiscard]] const char* path() const;
  /// Before recording a frame: on the CUDA path, CUDA copies the particles in.
  void refresh();

  /// The set the sphere pipeline reads the colour rule from (colors.glsl).
  [[nodiscard]] VkDescriptorSetLayout set_layout() const { return set_layout_; }
  /// Outside the render pass, before it: on the zero-copy path the barrier after motes' writes
  /// (and after the last frame's reads) and the speed reduction.
  void record_before(VkCommandBuffer cmd) const;
  /// Inside the render pass with the sphere or the shadow pipeline bound (`layout` their layout):
  /// the colours' set, the two per-instance buffers and the draw.
  void record_draw(VkCommandBuffer cmd, VkPipelineLayout layout) const;
  /// After the render pass: on the CUDA path the shared memory given back to CUDA.
  void record_after(VkCommandBuffer cmd) const;

 private:
  /// The zero-copy path's buffers: positions (binding 0), the second attribute (binding 1:
  /// per-particle colours, or the velocities), and the velocities for speed_max.comp.
  struct Direct {
    VkBuffer positions = VK_NULL_HANDLE;
    VkDeviceSize positions_offset = 0;
    VkBuffer attributes = VK_NULL_HANDLE;
    VkDeviceSize attributes_offset = 0;
    bool speed = false;
  };
  void write_colors(const ColorState& state);
  /// Draws from `positions` and `velocities` (in the device's particle order) from now on.
  void use(const Styler& styler, Simulation& sim, const Snapshot& first_frame,
           const VulkanParticleBuffers& buffers);

  const Gpu& gpu_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  VkPipelineLayout speed_layout_ = VK_NULL_HANDLE;
  VkPipeline speed_max_ = VK_NULL_HANDLE;
  HostBuffer colors_;                         ///< the ColorState
  std::unique_ptr<HostBuffer> staged_;        ///< staged: spheres, then colours
  VkDeviceSize staged_colors_offset_ = 0;     ///< where the colours start in staged_
  std::unique_ptr<DeviceBuffer> per_device_;  ///< zero copy: colours in the device's order
  std::optional<Direct> direct_;
  std::unique_ptr<CudaShare> shared_;  ///< the CUDA path's memory
  Simulation* shared_sim_ = nullptr;   ///< the simulation it copies from
  std::uint32_t count_ = 0;
};

}  // namespace motes::viewer
