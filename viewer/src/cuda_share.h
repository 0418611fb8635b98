// The CUDA path of `motes view` (docs/viewer.md, "How it draws"): device-local memory the viewer
// makes and exports (VK_KHR_external_memory_fd), imported by CUDA on the same GPU
// (motes/cuda_interop.h); before each draw CUDA copies the simulation's positions (and, for speed
// colours, velocities) into it device to device, and the sphere pipeline reads it as it reads
// motes' own buffers on the zero-copy path.
#pragma once

#include <memory>
#include <string>

#include "gpu.h"
#include "motes/simulation.h"

namespace motes::viewer {

class CudaShare {
 public:
  /// Why `sim` cannot be drawn this way on `gpu` (empty when it can): a build without CUDA, a
  /// simulation on another backend or on another GPU, a driver without the extension.
  static std::string why_not(const Gpu& gpu, Simulation& sim);
  /// Memory for `sim`'s positions and, with `velocities`, its velocities after them; throws
  /// std::runtime_error (one line) when the driver refuses.
  CudaShare(const Gpu& gpu, Simulation& sim, bool velocities);
  ~CudaShare();
  CudaShare(const CudaShare&) = delete;
  CudaShare& operator=(const CudaShare&) = delete;

  /// CUDA copies `sim`'s particles in; returns when they are there. Call it only while no
  /// submitted draw reads the memory.
  void copy(Simulation& sim);
  /// Around the draws that read it: the memory's ownership taken from CUDA (the external queue
  /// family) before, and given back after.
  void record_acquire(VkCommandBuffer cmd) const;
  void record_release(VkCommandBuffer cmd) const;

  [[nodiscard]] VkBuffer buffer() const { return buffer_; }
  [[nodiscard]] VkDeviceSize velocities_offset() const { return velocities_offset_; }
  [[nodiscard]] VkDeviceSize size() const { return size_; }

 private:
  struct Imported;
  const Gpu& gpu_;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  VkDeviceSize velocities_offset_ = 0;
  [[maybe_unused]] bool velocities_ = false;  // read only in a build with CUDA
  std::unique_ptr<Imported> imported_;
};

}  // namespace motes::viewer
